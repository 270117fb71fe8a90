// arview's pair matching for `arview map` (mapping/pair_matching.h): the pairs it matches, the
// matches it finds on descriptors with a known answer, the match lists COLMAP reads, and the
// merge of verified pairs from a database copy.

#include "mapping/pair_matching.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "map/map.h"

namespace arview::mapping {
namespace {

namespace fs = std::filesystem;

TEST(PairMatching, ExhaustivePairsAreEveryPairOnce) {
  const auto pairs = ExhaustivePairs(5);
  ASSERT_EQ(pairs.size(), 10u);
  EXPECT_EQ(pairs.front(), (ImagePair{0, 1}));
  EXPECT_EQ(pairs.back(), (ImagePair{3, 4}));
  EXPECT_TRUE(ExhaustivePairs(1).empty());
}

TEST(PairMatching, SequentialPairsFollowColmapsOverlapAndItsQuadraticLinks) {
  // Overlap 2: the next two images; quadratic adds i+1, i+2 (already there) for k < 2.
  const auto plain = SequentialPairs(5, 2, false);
  const std::vector<ImagePair> want{{0, 1}, {0, 2}, {1, 2}, {1, 3}, {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(plain, want);
  EXPECT_EQ(SequentialPairs(5, 2, true), want);
  // Overlap 3 with quadratic links: i+1, i+2, i+3 and i+4 (2^2).
  const auto quadratic = SequentialPairs(10, 3, true);
  const auto has = [&](int a, int b) {
    return std::find(quadratic.begin(), quadratic.end(), ImagePair{a, b}) != quadratic.end();
  };
  EXPECT_TRUE(has(0, 3));
  EXPECT_TRUE(has(0, 4));
  EXPECT_FALSE(has(0, 5));
  EXPECT_FALSE(has(0, 8));  // 2^3: k runs below the overlap
  EXPECT_TRUE(has(5, 9));
  // Each pair once.
  auto sorted = quadratic;
  std::sort(sorted.begin(), sorted.end(),
            [](const ImagePair& a, const ImagePair& b) { return std::tie(a.first, a.second) < std::tie(b.first, b.second); });
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
}

// `count` random descriptors scaled as COLMAP stores them (unit vectors x512, clamped to 255).
cv::Mat RandomDescriptors(int count, std::mt19937& rng) {
  cv::Mat d(count, 128, CV_8U);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int r = 0; r < count; ++r) {
    std::vector<float> v(128);
    float norm = 0;
    for (float& x : v) {
      x = u(rng) * u(rng);
      norm += x * x;
    }
    for (int c = 0; c < 128; ++c) d.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(std::min(255.f, 512.f * v[static_cast<size_t>(c)] / std::sqrt(norm)));
  }
  return d;
}

// Image B holds image A's first `shared` descriptors, shuffled and slightly changed, and
// descriptors of its own: the matches must be exactly the shared ones.
struct KnownMatches {
  std::vector<cv::Mat> descriptors;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> truth;  // sorted by A's row
};

KnownMatches MakeKnownMatches(int shared, int own, unsigned seed) {
  std::mt19937 rng(seed);
  const cv::Mat a = RandomDescriptors(shared + own, rng);
  cv::Mat b = RandomDescriptors(shared + own, rng);
  std::vector<int> place(static_cast<size_t>(shared + own));
  for (size_t i = 0; i < place.size(); ++i) place[i] = static_cast<int>(i);
  std::shuffle(place.begin(), place.end(), rng);
  KnownMatches k;
  std::uniform_int_distribution<int> noise(-2, 2);
  for (int r = 0; r < shared; ++r) {
    const int row = place[static_cast<size_t>(r)];
    for (int c = 0; c < 128; ++c)
      b.at<std::uint8_t>(row, c) = static_cast<std::uint8_t>(std::clamp(a.at<std::uint8_t>(r, c) + noise(rng), 0, 255));
    k.truth.emplace_back(static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(row));
  }
  k.descriptors = {a, b};
  return k;
}

TEST(PairMatching, FindsTheSharedFeaturesAndNothingElse) {
  const KnownMatches k = MakeKnownMatches(300, 500, 7);
  PairMatchingOptions o;
  const auto result = MatchImagePairs(k.descriptors, {{0, 1}}, o);
  ASSERT_EQ(result.size(), 1u);
  auto found = result[0].matches;
  std::sort(found.begin(), found.end());
  // The kd-trees are approximate: nearly all shared features, and no wrong match.
  EXPECT_GE(found.size(), 285u);
  for (const auto& m : found)
    EXPECT_TRUE(std::binary_search(k.truth.begin(), k.truth.end(), m)) << m.first << " " << m.second;
}

// COLMAP cannot verify a pair with fewer matches than it needs inliers: it is given none.
TEST(PairMatching, APairWithTooFewMatchesToVerifyGetsNone) {
  const KnownMatches k = MakeKnownMatches(10, 300, 11);
  PairMatchingOptions o;
  EXPECT_TRUE(MatchImagePairs(k.descriptors, {{0, 1}}, o)[0].matches.empty());
  o.min_matches = 5;
  EXPECT_GE(MatchImagePairs(k.descriptors, {{0, 1}}, o)[0].matches.size(), 9u);
}

TEST(PairMatching, TheSameMatchesWithAnyNumberOfThreads) {
  std::vector<cv::Mat> descriptors;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const KnownMatches k = MakeKnownMatches(100, 200, seed);
    descriptors.push_back(k.descriptors[0]);
    descriptors.push_back(k.descriptors[1]);
  }
  PairMatchingOptions one;
  one.threads = 1;
  PairMatchingOptions three = one;
  three.threads = 3;
  const auto pairs = ExhaustivePairs(static_cast<int>(descriptors.size()));
  int reported = 0;
  const auto a = MatchImagePairs(descriptors, pairs, one);
  const auto b = MatchImagePairs(descriptors, pairs, three, [&](int done, int total) {
    EXPECT_LE(done, total);
    reported = done;
  });
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].pair, b[i].pair);
    EXPECT_EQ(a[i].matches, b[i].matches) << i;
  }
  EXPECT_EQ(reported, static_cast<int>(pairs.size()));
}

TEST(PairMatching, CancelledMatchingStops) {
  const KnownMatches k = MakeKnownMatches(50, 50, 3);
  CancellationToken cancel;
  cancel.Cancel();
  EXPECT_THROW(MatchImagePairs(k.descriptors, {{0, 1}}, {}, {}, cancel), CancelledError);
}

TEST(PairMatching, APairOutsideTheImagesIsRefused) {
  const KnownMatches k = MakeKnownMatches(10, 10, 3);
  EXPECT_THROW(MatchImagePairs(k.descriptors, {{0, 2}}, {}), map::MapError);
  EXPECT_THROW(MatchImagePairs(k.descriptors, {{1, 1}}, {}), map::MapError);
}

std::string ReadText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(PairMatching, MatchListsAreColmapsRawFormatSplitByMatches) {
  const fs::path dir = fs::temp_directory_path() / ("arview_pair_lists_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::string> names{"frames/a.png", "frames/b.png", "frames/c.png"};
  std::vector<PairMatches> matches{{{0, 1}, {{0, 0}, {1, 2}, {2, 1}}}, {{0, 2}, {}}, {{1, 2}, {{4, 5}, {6, 7}}}};
  const std::vector<fs::path> parts{dir / "m0.txt", dir / "m1.txt"};
  WriteMatchLists(names, matches, parts);
  // The biggest pair alone in the first part, the next in the second; the empty pair nowhere.
  EXPECT_EQ(ReadText(parts[0]), "frames/a.png frames/b.png\n0 0\n1 2\n2 1\n\n");
  EXPECT_EQ(ReadText(parts[1]), "frames/b.png frames/c.png\n4 5\n6 7\n\n");
  fs::remove_all(dir);
}

void Exec(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
}

// A database with COLMAP's two match tables and the given pair ids.
void MakeDatabase(const fs::path& file, const std::vector<int>& pair_ids) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  Exec(db,
       "CREATE TABLE matches(pair_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols INTEGER NOT NULL, "
       "data BLOB);"
       "CREATE TABLE two_view_geometries(pair_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols INTEGER "
       "NOT NULL, data BLOB, config INTEGER NOT NULL, F BLOB, E BLOB, H BLOB, qvec BLOB, tvec BLOB);");
  for (int id : pair_ids) {
    Exec(db, "INSERT INTO matches VALUES(" + std::to_string(id) + ", 3, 2, NULL);");
    Exec(db, "INSERT INTO two_view_geometries VALUES(" + std::to_string(id) + ", 2, 2, NULL, 2, NULL, NULL, NULL, NULL, NULL);");
  }
  sqlite3_close(db);
}

// Each row of a query, its columns joined by ':'.
std::vector<std::string> Rows(const fs::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  sqlite3_open(file.c_str(), &db);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr);
  std::vector<std::string> rows;
  while (sqlite3_step(st) == SQLITE_ROW) {
    std::string row;
    for (int c = 0; c < sqlite3_column_count(st); ++c) {
      const unsigned char* text = sqlite3_column_text(st, c);
      row += (c ? ":" : "") + std::string(text ? reinterpret_cast<const char*>(text) : "NULL");
    }
    rows.push_back(row);
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  return rows;
}

int Count(const fs::path& file, const std::string& table) {
  const std::vector<std::string> rows = Rows(file, "SELECT count(*) FROM " + table);
  return rows.empty() ? -1 : std::stoi(rows[0]);
}

TEST(PairMatching, VerifiedPairsOfACopyAreAddedToTheDatabase) {
  const fs::path dir = fs::temp_directory_path() / ("arview_pair_merge_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  MakeDatabase(dir / "main db.db", {1, 2});
  MakeDatabase(dir / "part's copy.db", {3, 4, 5});
  MergeVerifiedPairs(dir / "main db.db", dir / "part's copy.db");
  EXPECT_EQ(Count(dir / "main db.db", "matches"), 5);
  EXPECT_EQ(Count(dir / "main db.db", "two_view_geometries"), 5);
  // A part that is not a database is named.
  { std::ofstream(dir / "junk.db") << "not a database"; }
  try {
    MergeVerifiedPairs(dir / "main db.db", dir / "junk.db");
    ADD_FAILURE() << "merged a file that is not a database";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.db"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Count(dir / "main db.db", "matches"), 5);
  fs::remove_all(dir);
}

// A database of feature_extractor's tables (the columns arview reads) holding `names` with
// image ids 1, 2, ..., each with keypoints and descriptors whose rows are its id times 10, and
// one camera whose width is `width`.
void MakeExtractedDatabase(const fs::path& file, const std::vector<std::string>& names, int width = 640) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  Exec(db,
       "CREATE TABLE cameras(camera_id INTEGER PRIMARY KEY NOT NULL, model INTEGER NOT NULL, width INTEGER NOT NULL, "
       "height INTEGER NOT NULL, params BLOB, prior_focal_length INTEGER NOT NULL);"
       "CREATE TABLE images(image_id INTEGER PRIMARY KEY NOT NULL, name TEXT NOT NULL UNIQUE, camera_id INTEGER NOT "
       "NULL, prior_qw REAL, CONSTRAINT image_id_check CHECK(image_id >= 0 and image_id < 2147483647));"
       "CREATE TABLE keypoints(image_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols INTEGER NOT NULL, "
       "data BLOB);"
       "CREATE TABLE descriptors(image_id INTEGER PRIMARY KEY NOT NULL, rows INTEGER NOT NULL, cols INTEGER NOT NULL, "
       "data BLOB);"
       "INSERT INTO cameras VALUES(1, 4, " + std::to_string(width) + ", 480, x'0102', 1);");
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string id = std::to_string(i + 1), rows = std::to_string(10 * (i + 1));
    Exec(db, "INSERT INTO images VALUES(" + id + ", '" + names[i] + "', 1, NULL);");
    Exec(db, "INSERT INTO keypoints VALUES(" + id + ", " + rows + ", 6, NULL);");
    Exec(db, "INSERT INTO descriptors VALUES(" + id + ", " + rows + ", 128, NULL);");
  }
  sqlite3_close(db);
}

// "id:name:keypoint rows:descriptor rows " of every image, by id.
std::string ImagesOf(const fs::path& file) {
  std::string text;
  for (const std::string& row : Rows(file,
                                     "SELECT images.image_id, name, keypoints.rows, descriptors.rows FROM images JOIN "
                                     "keypoints USING (image_id) JOIN descriptors USING (image_id) ORDER BY images.image_id"))
    text += row + " ";
  return text;
}

TEST(PairMatching, ImagesExtractedInAnotherDatabaseAreAddedAfterTheDatabasesOwn) {
  const fs::path dir = fs::temp_directory_path() / ("arview_extract_merge_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  MakeExtractedDatabase(dir / "main.db", {"f/0.png", "f/1.png"});
  MakeExtractedDatabase(dir / "chunk 1.db", {"f/2.png", "f/3.png", "f/4.png"});
  MergeExtractedImages(dir / "main.db", dir / "chunk 1.db");
  // Each image keeps its own keypoints and descriptors under its new id.
  EXPECT_EQ(ImagesOf(dir / "main.db"), "1:f/0.png:10:10 2:f/1.png:20:20 3:f/2.png:10:10 4:f/3.png:20:20 5:f/4.png:30:30 ");
  EXPECT_EQ(Count(dir / "main.db", "cameras"), 1);
  const std::string merged = ImagesOf(dir / "main.db");

  // Another camera, or an image the database holds already: refused, the database as it was.
  MakeExtractedDatabase(dir / "other camera.db", {"f/5.png"}, 1280);
  try {
    MergeExtractedImages(dir / "main.db", dir / "other camera.db");
    ADD_FAILURE() << "merged another camera's images";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("its camera is not the database's one camera"), std::string::npos) << e.what();
  }
  MakeExtractedDatabase(dir / "again.db", {"f/6.png", "f/1.png"});
  try {
    MergeExtractedImages(dir / "main.db", dir / "again.db");
    ADD_FAILURE() << "merged an image twice";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("again.db"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("UNIQUE"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ImagesOf(dir / "main.db"), merged);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview::mapping
