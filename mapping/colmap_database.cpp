#include "mapping/colmap_database.h"
#include "map/descriptor_size.h"

#include <sqlite3.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstring>

#include "base/input_guard.h"
#include "map/map_file.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// How long a write waits for another process's lock (a job merging its part) before failing.
constexpr int kBusyTimeoutMs = 5000;

void RequireDatabaseFile(const fs::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw map::MapError(path.string() + ": COLMAP database missing");
  if (!S_ISREG(st.st_mode))
    throw map::MapError(path.string() + ": is " + FileKindOf(st.st_mode) + ", not a COLMAP database file");
}

}  // namespace

void ColmapDatabase::Closer::operator()(sqlite3* db) const { sqlite3_close(db); }

// A prepared statement, finalized when it goes out of scope; a query SQLite cannot prepare is
// the database's error.
class ColmapDatabase::Statement {
 public:
  Statement(const ColmapDatabase& db, const char* sql) {
    if (sqlite3_prepare_v2(db.db_.get(), sql, -1, &st_, nullptr) != SQLITE_OK) {
      sqlite3_finalize(st_);
      db.Fail(std::string("cannot prepare the query '") + sql + "'");
    }
  }
  ~Statement() { sqlite3_finalize(st_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() { return st_; }

 private:
  sqlite3_stmt* st_ = nullptr;
};

ColmapDatabase::ColmapDatabase(const fs::path& path, Access access) : path_(path) {
  RequireDatabaseFile(path);
  sqlite3* db = nullptr;
  const int flags = access == Access::kRead ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  db_.reset(db);
  if (rc != SQLITE_OK) Fail("cannot open");
  if (access == Access::kReadWrite) sqlite3_busy_timeout(db, kBusyTimeoutMs);
}

ColmapDatabase::~ColmapDatabase() = default;

void ColmapDatabase::Fail(const std::string& problem) const {
  const std::string detail = db_ ? sqlite3_errmsg(db_.get()) : "out of memory";
  throw map::MapError(path_.string() + ": " + problem + " (SQLite: " + detail + ")");
}

std::vector<ColmapDatabase::ImageRow> ColmapDatabase::Images() {
  std::vector<ImageRow> images;
  Statement st(*this, "SELECT image_id, name, camera_id FROM images ORDER BY image_id");
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(st.get())) == SQLITE_ROW) {
    const sqlite3_int64 id = sqlite3_column_int64(st.get(), 0);
    if (id <= 0 || id > kColmapMaxNumImages) Fail("an image has the id " + std::to_string(id) + ", not one COLMAP gives");
    const unsigned char* text = sqlite3_column_text(st.get(), 1);
    images.push_back({static_cast<std::uint32_t>(id), text ? reinterpret_cast<const char*>(text) : "",
                      sqlite3_column_int64(st.get(), 2)});
  }
  if (rc != SQLITE_DONE) Fail("reading images");
  return images;
}

std::uint32_t ColmapDatabase::ImageId(const std::string& name) {
  Statement st(*this, "SELECT image_id FROM images WHERE name = ?");
  sqlite3_bind_text(st.get(), 1, name.c_str(), -1, SQLITE_TRANSIENT);
  const int rc = sqlite3_step(st.get());
  if (rc == SQLITE_DONE) Fail("no image named " + name);
  if (rc != SQLITE_ROW) Fail("reading the id of image " + name);
  const sqlite3_int64 id = sqlite3_column_int64(st.get(), 0);
  if (id <= 0 || id > kColmapMaxNumImages) Fail("image " + name + " has the id " + std::to_string(id) + ", not one COLMAP gives");
  return static_cast<std::uint32_t>(id);
}

std::string ColmapDatabase::ImageName(std::uint32_t image_id) {
  Statement st(*this, "SELECT name FROM images WHERE image_id = ?");
  sqlite3_bind_int64(st.get(), 1, image_id);
  const int rc = sqlite3_step(st.get());
  if (rc == SQLITE_DONE) Fail("no image with id " + std::to_string(image_id) + " (not the model's database?)");
  if (rc != SQLITE_ROW) Fail("reading image id " + std::to_string(image_id));
  const unsigned char* text = sqlite3_column_text(st.get(), 0);
  return text ? reinterpret_cast<const char*>(text) : "";
}

cv::Mat ColmapDatabase::Descriptors(std::uint32_t image_id) {
  Statement st(*this, "SELECT rows, cols, data FROM descriptors WHERE image_id = ?");
  sqlite3_bind_int64(st.get(), 1, image_id);
  const int rc = sqlite3_step(st.get());
  if (rc == SQLITE_DONE) Fail("no descriptors for image id " + std::to_string(image_id));
  if (rc != SQLITE_ROW) Fail("reading descriptors of image id " + std::to_string(image_id));
  const sqlite3_int64 rows = sqlite3_column_int64(st.get(), 0);
  const sqlite3_int64 cols = sqlite3_column_int64(st.get(), 1);
  const void* blob = sqlite3_column_blob(st.get(), 2);
  const sqlite3_int64 bytes = sqlite3_column_bytes(st.get(), 2);
  if (cols != map::kDescriptorSize || rows < 0 || rows > (1 << 24) || bytes != rows * cols || (rows > 0 && !blob)) {
    Fail("descriptors of image id " + std::to_string(image_id) + " have a wrong shape (" + std::to_string(rows) + " x " +
         std::to_string(cols) + ", " + std::to_string(bytes) + " bytes; expected uint8 x 128)");
  }
  cv::Mat m(static_cast<int>(rows), map::kDescriptorSize, CV_8UC1);
  if (rows > 0) std::memcpy(m.data, blob, static_cast<size_t>(bytes));
  return m;
}

std::vector<ColmapDatabase::PairGeometry> ColmapDatabase::PairGeometries() {
  std::vector<PairGeometry> pairs;
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db_.get(), "SELECT pair_id, rows, E, config, F, cols, data FROM two_view_geometries WHERE rows > 0", -1, &raw,
                         nullptr) != SQLITE_OK) {
    sqlite3_finalize(raw);
    return pairs;
  }
  const std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> st(raw, sqlite3_finalize);
  while (sqlite3_step(st.get()) == SQLITE_ROW) {
    const sqlite3_int64 pair_id = sqlite3_column_int64(st.get(), 0);
    const void* blob = sqlite3_column_blob(st.get(), 2);
    if (pair_id < 0 || !blob || sqlite3_column_bytes(st.get(), 2) != 9 * sizeof(double)) continue;
    PairGeometry g;
    g.image_a = static_cast<std::uint32_t>(pair_id / kColmapMaxNumImages);
    g.image_b = static_cast<std::uint32_t>(pair_id % kColmapMaxNumImages);
    g.inliers = static_cast<int>(std::min<sqlite3_int64>(sqlite3_column_int64(st.get(), 1), 1 << 30));
    g.config = sqlite3_column_int(st.get(), 3);
    // COLMAP writes its matrices transposed, i.e. row by row (database.cc); x_b^T E x_a = 0.
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rows_first;
    std::memcpy(rows_first.data(), blob, 9 * sizeof(double));
    g.essential = rows_first;
    const void* f_blob = sqlite3_column_blob(st.get(), 4);
    if (f_blob && sqlite3_column_bytes(st.get(), 4) == 9 * sizeof(double)) {
      std::memcpy(rows_first.data(), f_blob, 9 * sizeof(double));
      g.fundamental = rows_first;
    }
    const void* match_blob = sqlite3_column_blob(st.get(), 6);
    const sqlite3_int64 match_bytes = sqlite3_column_bytes(st.get(), 6);
    if (match_blob && sqlite3_column_int64(st.get(), 5) == 2 &&
        match_bytes == static_cast<sqlite3_int64>(g.inliers) * 2 * static_cast<sqlite3_int64>(sizeof(std::uint32_t))) {
      g.matches.resize(static_cast<std::size_t>(g.inliers));
      std::memcpy(g.matches.data(), match_blob, static_cast<std::size_t>(match_bytes));
    }
    pairs.push_back(std::move(g));
  }
  return pairs;
}

std::vector<VerifiedPair> ColmapDatabase::VerifiedPairs() {
  std::vector<VerifiedPair> pairs;
  Statement st(*this, "SELECT pair_id, rows FROM two_view_geometries WHERE rows > 0");
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(st.get())) == SQLITE_ROW) {
    const sqlite3_int64 pair_id = sqlite3_column_int64(st.get(), 0);
    if (pair_id < 0) Fail("a two-view geometry has the negative pair id " + std::to_string(pair_id));
    pairs.push_back({static_cast<std::uint32_t>(pair_id / kColmapMaxNumImages),
                     static_cast<std::uint32_t>(pair_id % kColmapMaxNumImages),
                     static_cast<int>(std::min<sqlite3_int64>(sqlite3_column_int64(st.get(), 1), 1 << 30))});
  }
  if (rc != SQLITE_DONE) Fail("reading two_view_geometries");
  return pairs;
}

void ColmapDatabase::Execute(const std::string& sql, const std::string& what) {
  char* error = nullptr;
  if (sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : sqlite3_errmsg(db_.get());
    sqlite3_free(error);
    // A transaction the SQL opened is not left open (a no-op when none is).
    sqlite3_exec(db_.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    throw map::MapError(path_.string() + ": cannot " + what + " (SQLite: " + why + ")");
  }
}

void ColmapDatabase::ExecuteWithPart(const fs::path& part, const std::string& sql, const std::string& what,
                                     const std::string& precondition, const std::string& refusal) {
  {
    Statement attach(*this, "ATTACH DATABASE ? AS part");
    if (sqlite3_bind_text(attach.get(), 1, part.c_str(), -1, SQLITE_TRANSIENT) != SQLITE_OK ||
        sqlite3_step(attach.get()) != SQLITE_DONE)
      Fail("cannot " + what + ": attaching it failed");
  }
  // Detached however this ends (its statements finalized first: SQLite refuses to detach a
  // database a live statement reads), so that the next part can be attached by the same name.
  struct Detach {
    sqlite3* db;
    ~Detach() { sqlite3_exec(db, "DETACH DATABASE part", nullptr, nullptr, nullptr); }
  } detach{db_.get()};
  if (!precondition.empty()) {
    bool holds = false;
    {
      Statement check(*this, precondition.c_str());
      holds = sqlite3_step(check.get()) == SQLITE_ROW && sqlite3_column_int(check.get(), 0) == 1;
    }
    if (!holds) throw map::MapError(path_.string() + ": cannot " + what + " (" + refusal + ")");
  }
  Execute(sql, what);
}

void ColmapDatabase::SetSingleCameraParams(const std::vector<double>& params) {
  Statement st(*this, "UPDATE cameras SET params = ?");
  const bool ok = sqlite3_bind_blob(st.get(), 1, params.data(), static_cast<int>(params.size() * sizeof(double)),
                                    SQLITE_TRANSIENT) == SQLITE_OK &&
                  sqlite3_step(st.get()) == SQLITE_DONE;
  if (!ok) Fail("cannot set its camera's parameters");
  const int changed = sqlite3_changes(db_.get());
  if (changed != 1) {
    throw map::MapError(path_.string() + ": cannot set its camera's parameters (" + std::to_string(changed) +
                        " cameras; one camera expected)");
  }
}

void ColmapDatabase::CopyTo(const fs::path& copy) {
  RemoveColmapDatabase(copy);
  Statement st(*this, "VACUUM INTO ?");
  const bool ok = sqlite3_bind_text(st.get(), 1, copy.c_str(), -1, SQLITE_TRANSIENT) == SQLITE_OK &&
                  sqlite3_step(st.get()) == SQLITE_DONE;
  if (!ok) {
    const std::string why = sqlite3_errmsg(db_.get());
    RemoveColmapDatabase(copy);
    throw map::MapError(path_.string() + ": cannot copy it to " + copy.string() + " (SQLite: " + why + ")");
  }
}

void CopyColmapDatabase(const fs::path& database, const fs::path& copy) {
  ColmapDatabase(database, ColmapDatabase::Access::kRead).CopyTo(copy);
}

void RemoveColmapDatabase(const fs::path& database) {
  std::error_code ec;
  for (const char* suffix : {"", "-shm", "-wal", "-journal"}) fs::remove(database.string() + suffix, ec);
}

}  // namespace arview::mapping
