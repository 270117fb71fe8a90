#pragma once
// COLMAP's database (database.db, SQLite): the one place mapping/ opens it. Reads are what the
// map's reader, the map check, the match graph and `map extend` need; writes are arview's own
// edits between COLMAP's stages (clearing old matches, merging the parts that jobs extracted and
// matched, the camera of a self-calibrated map, a consistent copy). Every failure is a
// map::MapError naming the file, what was being done and SQLite's reason.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

struct sqlite3;

namespace arview::mapping {

// COLMAP's pair id: image_id1 * kColmapMaxNumImages + image_id2, image_id1 < image_id2.
inline constexpr std::int64_t kColmapMaxNumImages = 2147483647;

// One pair of images COLMAP verified (two_view_geometries), by COLMAP's image ids.
struct VerifiedPair {
  std::uint32_t image_a = 0, image_b = 0;
  int inliers = 0;
};

// A verified pair's fundamental matrix, in COLMAP's pixels (centres at +0.5): x_b^T F x_a = 0.
struct FundamentalPair {
  std::uint32_t image_a = 0, image_b = 0;  // COLMAP's image ids
  int inliers = 0;
  Eigen::Matrix3d fundamental;
};

class ColmapDatabase {
 public:
  enum class Access { kRead, kReadWrite };

  // Opens an existing database. Not there: "<path>: COLMAP database missing"; there but not a
  // regular file (a FIFO, a folder): says what it is; SQLite refusing it: "<path>: cannot open
  // (SQLite: ...)".
  ColmapDatabase(const std::filesystem::path& path, Access access);
  ~ColmapDatabase();
  ColmapDatabase(const ColmapDatabase&) = delete;
  ColmapDatabase& operator=(const ColmapDatabase&) = delete;

  const std::filesystem::path& path() const { return path_; }

  // --- Reads ---
  struct ImageRow {
    std::uint32_t id = 0;
    std::string name;
    std::int64_t camera_id = 0;
  };
  // Every image, by id; an id COLMAP never gives is refused.
  std::vector<ImageRow> Images();
  std::uint32_t ImageId(const std::string& name);
  std::string ImageName(std::uint32_t image_id);
  // The SIFT descriptors of one image (rows x 128, CV_8U); a wrong shape is refused.
  cv::Mat Descriptors(std::uint32_t image_id);

  // A verified pair's geometry as COLMAP stored it (two_view_geometries).
  struct PairGeometry {
    std::uint32_t image_a = 0, image_b = 0;
    int inliers = 0;
    int config = 0;  // COLMAP's TwoViewGeometry::ConfigurationType
    Eigen::Matrix3d essential = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d fundamental = Eigen::Matrix3d::Zero();  // zero where COLMAP stored none
    // The verified matches (keypoint index in image_a, in image_b); empty where the blob is not
    // `inliers` rows of two uint32 (then the map check compares the rotations alone).
    std::vector<std::array<std::uint32_t, 2>> matches;
  };
  // Nothing when the table or its E column is absent (a database of another COLMAP version): the
  // map check then skips the comparison.
  std::vector<PairGeometry> PairGeometries();
  // Every verified pair with inliers, whatever its configuration (the match graph).
  std::vector<VerifiedPair> VerifiedPairs();

  // --- Writes (kReadWrite) ---
  // Runs `sql` (statements, a transaction of its own if it says BEGIN ... COMMIT; rolled back when
  // one fails). `what` names the step for the error: "<path>: cannot <what> (SQLite: ...)".
  void Execute(const std::string& sql, const std::string& what);
  // The same with the database `part` attached as "part" (its path bound, never spliced into the
  // SQL). `precondition`, when not empty, is a query run first whose one value must be 1, else
  // the error's reason is `refusal`.
  void ExecuteWithPart(const std::filesystem::path& part, const std::string& sql, const std::string& what,
                       const std::string& precondition = "", const std::string& refusal = "");
  // Replaces the parameters of the database's one camera, in COLMAP's order for its model.
  void SetSingleCameraParams(const std::vector<double>& params);
  // A consistent copy into `copy` (VACUUM INTO: whatever the journal holds is in it); a copy that
  // failed is removed.
  void CopyTo(const std::filesystem::path& copy);

 private:
  class Statement;
  [[noreturn]] void Fail(const std::string& problem) const;

  std::filesystem::path path_;
  struct Closer {
    void operator()(sqlite3* db) const;
  };
  std::unique_ptr<sqlite3, Closer> db_;
};

// A consistent copy of a COLMAP database (its journal included); removing one with its journal.
void CopyColmapDatabase(const std::filesystem::path& database, const std::filesystem::path& copy);
void RemoveColmapDatabase(const std::filesystem::path& database);

}  // namespace arview::mapping
