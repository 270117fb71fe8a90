#include "mapping/colmap_model.h"
#include "map/descriptor_size.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "base/input_guard.h"
#include "base/library_errors.h"
#include "map/map_file.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// A whole file in memory with bounds-checked little-endian reads.
class BinaryReader {
 public:
  // Only a regular file of a sane size is read (a link to /dev/zero or a FIFO would never
  // end), in chunks that look at `cancel`.
  BinaryReader(const fs::path& path, const CancellationToken& cancel) : path_(path) {
    try {
      data_ = NamingInput<map::MapError>(path.string(), [&] { return ReadFileUpTo(path, kMaxBinaryFileBytes, cancel); });
    } catch (const InputError& e) {
      throw map::MapError(e.what());
    }
  }

  template <typename T>
  T Read(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    Need(sizeof(T), what);
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  std::string ReadCString(const char* what) {
    const auto begin = data_.begin() + static_cast<std::ptrdiff_t>(pos_);
    const auto end = std::find(begin, data_.end(), '\0');
    if (end == data_.end()) Fail(std::string("truncated inside ") + what);
    std::string s(begin, end);
    pos_ += s.size() + 1;
    return s;
  }

  // A count read from the file, checked against the bytes left so that a corrupted count
  // fails here instead of in a huge allocation.
  std::uint64_t ReadCount(const char* what, std::size_t min_record_bytes) {
    const auto n = Read<std::uint64_t>(what);
    if (min_record_bytes > 0 && n > Remaining() / min_record_bytes) {
      Fail(std::string(what) + " = " + std::to_string(n) + " does not fit in the " +
           std::to_string(Remaining()) + " bytes left (truncated or corrupted)");
    }
    return n;
  }

  std::size_t Remaining() const { return data_.size() - pos_; }
  void ExpectEnd() const {
    if (Remaining() != 0) Fail(std::to_string(Remaining()) + " unexpected bytes after the last record");
  }
  [[noreturn]] void Fail(const std::string& problem) const {
    throw map::MapError(path_.string() + ": " + problem + " (at byte " + std::to_string(pos_) + ")");
  }

 private:
  void Need(std::size_t n, const char* what) const {
    if (Remaining() < n) Fail(std::string("truncated while reading ") + what);
  }

  fs::path path_;
  std::string data_;
  std::size_t pos_ = 0;
};

// A value as read, for messages (nan and inf spelled out, 6 significant digits).
std::string Number(double value) {
  std::ostringstream s;
  s << std::setprecision(6) << value;
  return s.str();
}

// "(a, b, c)" of Number()s.
std::string Tuple(std::initializer_list<double> values) {
  std::string text = "(";
  for (const double v : values) text += (text.size() > 1 ? ", " : "") + Number(v);
  return text + ")";
}

int NumParams(int model_id) {
  switch (model_id) {
    case 0: return 3;   // SIMPLE_PINHOLE f, cx, cy
    case 1: return 4;   // PINHOLE fx, fy, cx, cy
    case 2: return 4;   // SIMPLE_RADIAL f, cx, cy, k
    case 3: return 5;   // RADIAL f, cx, cy, k1, k2
    case 4: return 8;   // OPENCV fx, fy, cx, cy, k1, k2, p1, p2
    case 5: return 8;   // OPENCV_FISHEYE
    case 6: return 12;  // FULL_OPENCV
    case 7: return 5;   // FOV
    case 8: return 4;   // SIMPLE_RADIAL_FISHEYE
    case 9: return 5;   // RADIAL_FISHEYE
    case 10: return 12; // THIN_PRISM_FISHEYE
    default: return -1;
  }
}

// COLMAP's camera to the shared OpenCV-convention camera (principal point − 0.5).
calib::Camera ToCamera(int model_id, std::uint64_t width, std::uint64_t height, const std::vector<double>& p,
                       const fs::path& file) {
  calib::Camera c;
  c.width = static_cast<int>(width);
  c.height = static_cast<int>(height);
  switch (model_id) {
    case 0: c.fx = c.fy = p[0]; c.cx = p[1]; c.cy = p[2]; break;
    case 1: c.fx = p[0]; c.fy = p[1]; c.cx = p[2]; c.cy = p[3]; break;
    case 2: c.fx = c.fy = p[0]; c.cx = p[1]; c.cy = p[2]; c.dist[0] = p[3]; break;
    case 3: c.fx = c.fy = p[0]; c.cx = p[1]; c.cy = p[2]; c.dist[0] = p[3]; c.dist[1] = p[4]; break;
    case 4:
      c.fx = p[0]; c.fy = p[1]; c.cx = p[2]; c.cy = p[3];
      c.dist = {p[4], p[5], p[6], p[7], 0.0};
      break;
    case 6:  // FULL_OPENCV: OpenCV's rational model; arview uses it only for k3 (k4..k6 = 0)
      if (p[9] != 0 || p[10] != 0 || p[11] != 0) {
        throw map::MapError(file.string() + ": FULL_OPENCV camera with rational terms k4..k6 is not supported");
      }
      c.fx = p[0]; c.fy = p[1]; c.cx = p[2]; c.cy = p[3];
      c.dist = {p[4], p[5], p[6], p[7], p[8]};
      break;
    default:
      throw map::MapError(file.string() + ": camera model " + std::to_string(model_id) +
                     " has no OpenCV radial-tangential equivalent (arview maps use OPENCV)");
  }
  c.cx -= 0.5;
  c.cy -= 0.5;
  try {
    c.Validate(file.string());
  } catch (const calib::CameraError& e) {
    throw map::MapError(e.what());
  }
  return c;
}

std::unordered_map<std::uint32_t, calib::Camera> ReadCameras(const fs::path& file, const CancellationToken& cancel) {
  BinaryReader r(file, cancel);
  const auto n = r.ReadCount("camera count", 4 + 4 + 8 + 8);
  std::unordered_map<std::uint32_t, calib::Camera> cameras;
  for (std::uint64_t i = 0; i < n; ++i) {
    const auto id = r.Read<std::uint32_t>("camera id");
    const auto model = r.Read<std::int32_t>("camera model");
    const auto width = r.Read<std::uint64_t>("camera width");
    const auto height = r.Read<std::uint64_t>("camera height");
    const int np = NumParams(model);
    if (np < 0) r.Fail("unknown camera model id " + std::to_string(model));
    if (width == 0 || height == 0 || width > 100000 || height > 100000) {
      r.Fail("camera " + std::to_string(id) + " has an impossible size " + std::to_string(width) + "x" +
             std::to_string(height));
    }
    std::vector<double> params(static_cast<size_t>(np));
    for (double& v : params) v = r.Read<double>("camera parameters");
    for (std::size_t k = 0; k < params.size(); ++k) {
      if (!std::isfinite(params[k])) {
        r.Fail("camera " + std::to_string(id) + "'s parameter " + std::to_string(k) + " (of " +
               std::to_string(params.size()) + ", model " + std::to_string(model) + ") is " + Number(params[k]) +
               ": every camera parameter must be a finite number");
      }
    }
    if (!cameras.emplace(id, ToCamera(model, width, height, params, file)).second) {
      r.Fail("camera id " + std::to_string(id) + " appears twice");
    }
  }
  r.ExpectEnd();
  return cameras;
}

std::vector<ColmapImage> ReadImages(const fs::path& file, const CancellationToken& cancel) {
  BinaryReader r(file, cancel);
  const auto n = r.ReadCount("registered image count", 4 + 7 * 8 + 4 + 1 + 8);
  std::vector<ColmapImage> images;
  images.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    ColmapImage im;
    im.id = r.Read<std::uint32_t>("image id");
    double q[4], t[3];
    for (double& v : q) v = r.Read<double>("image rotation");
    for (double& v : t) v = r.Read<double>("image translation");
    im.camera_id = r.Read<std::uint32_t>("image camera id");
    im.name = r.ReadCString("image name");
    const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
    if (!std::isfinite(quat.norm()) || std::abs(quat.norm() - 1.0) > 1e-3 ||
        !Eigen::Vector3d(t[0], t[1], t[2]).allFinite()) {
      r.Fail("image " + std::to_string(im.id) + " ('" + PrintableForMessage(im.name) + "') has the rotation (qw, qx, qy, qz) " +
             Tuple({q[0], q[1], q[2], q[3]}) + " and the translation " + Tuple({t[0], t[1], t[2]}) +
             ": a pose needs a unit quaternion and a finite translation");
    }
    im.pose.q_cw = quat.normalized();
    im.pose.t_cw = Eigen::Vector3d(t[0], t[1], t[2]);
    const auto np = r.ReadCount("2D point count", 8 + 8 + 8);
    im.xy.resize(np);
    im.point3d_ids.resize(np);
    for (std::uint64_t k = 0; k < np; ++k) {
      const double x = r.Read<double>("2D point x");
      const double y = r.Read<double>("2D point y");
      // Refused here, naming the value: a NaN pixel went on to fail the map's own validation as
      // "keyframe 13 has an observation with an index out of range".
      if (!std::isfinite(x) || !std::isfinite(y)) {
        r.Fail("image " + std::to_string(im.id) + " ('" + PrintableForMessage(im.name) + "') has its 2D point " +
               std::to_string(k) + " at " + Tuple({x, y}) + ": pixel coordinates must be finite numbers");
      }
      im.xy[k] = {x, y};
      im.point3d_ids[k] = r.Read<std::uint64_t>("2D point's 3D point id");
    }
    images.push_back(std::move(im));
  }
  r.ExpectEnd();
  return images;
}

std::vector<ColmapPoint> ReadPoints(const fs::path& file, const CancellationToken& cancel) {
  BinaryReader r(file, cancel);
  const auto n = r.ReadCount("3D point count", 8 + 24 + 3 + 8 + 8);
  std::vector<ColmapPoint> points;
  points.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    ColmapPoint p;
    p.id = r.Read<std::uint64_t>("3D point id");
    for (int k = 0; k < 3; ++k) p.point.xyz[k] = r.Read<double>("3D point position");
    for (int k = 0; k < 3; ++k) p.point.rgb[static_cast<size_t>(k)] = r.Read<std::uint8_t>("3D point colour");
    p.point.reprojection_error = r.Read<double>("3D point error");
    if (!p.point.xyz.allFinite() || !std::isfinite(p.point.reprojection_error)) {
      r.Fail("3D point " + std::to_string(p.id) + " has the position " +
             Tuple({p.point.xyz.x(), p.point.xyz.y(), p.point.xyz.z()}) + " and the error " +
             Number(p.point.reprojection_error) + ": both must be finite numbers");
    }
    const auto len = r.ReadCount("track length", 8);
    if (len == 0) r.Fail("3D point " + std::to_string(p.id) + " has an empty track");
    p.track.resize(len);
    for (auto& e : p.track) {
      e.image_id = r.Read<std::uint32_t>("track image id");
      e.point2d_idx = r.Read<std::uint32_t>("track 2D point index");
    }
    points.push_back(std::move(p));
  }
  r.ExpectEnd();
  return points;
}

std::uint64_t Key(std::uint32_t image_id, std::uint32_t point2d_idx) {
  return (static_cast<std::uint64_t>(image_id) << 32) | point2d_idx;
}

// One camera for all keyframes (arview runs COLMAP with --ImageReader.single_camera 1).
calib::Camera TheOneCamera(const std::unordered_map<std::uint32_t, calib::Camera>& cameras, const std::vector<ColmapImage>& images,
                           const fs::path& cameras_file, const fs::path& images_file) {
  const std::uint32_t camera_id = images.front().camera_id;
  for (const auto& im : images) {
    if (im.camera_id != camera_id) {
      throw map::MapError(images_file.string() + ": images use several cameras (" + std::to_string(camera_id) + ", " +
                     std::to_string(im.camera_id) + "); arview maps have one");
    }
  }
  const auto cam = cameras.find(camera_id);
  if (cam == cameras.end()) {
    throw map::MapError(images_file.string() + ": camera id " + std::to_string(camera_id) + " is not in " +
                   cameras_file.string());
  }
  return cam->second;
}

// Track elements must name registered images and 2D points that point back at them.
void RequireTracksReferBack(const std::vector<ColmapPoint>& points, const std::vector<ColmapImage>& images,
                            const std::unordered_map<std::uint32_t, std::uint32_t>& keyframe_of_image,
                            const fs::path& points_file, const fs::path& images_file) {
  for (const auto& p : points) {
    for (const auto& e : p.track) {
      const auto kf = keyframe_of_image.find(e.image_id);
      if (kf == keyframe_of_image.end()) {
        throw map::MapError(points_file.string() + ": 3D point " + std::to_string(p.id) + " is seen by image id " +
                       std::to_string(e.image_id) + ", which is not in " + images_file.string());
      }
      const auto& im = images[kf->second];
      if (e.point2d_idx >= im.point3d_ids.size() || im.point3d_ids[e.point2d_idx] != p.id) {
        throw map::MapError(points_file.string() + ": 3D point " + std::to_string(p.id) + "'s track names 2D point " +
                       std::to_string(e.point2d_idx) + " of image '" + PrintableForMessage(im.name) + "', which does not refer back to it");
      }
    }
  }
}

// Every keypoint of every image, in OpenCV's pixels, in the order of `images`.
std::vector<std::vector<Eigen::Vector2f>> AllKeypoints(const std::vector<ColmapImage>& images) {
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  for (const auto& im : images) {
    std::vector<Eigen::Vector2f>& all = keypoints.emplace_back();
    all.reserve(im.xy.size());
    for (const Eigen::Vector2d& xy : im.xy) all.push_back((xy - Eigen::Vector2d(0.5, 0.5)).cast<float>());
  }
  return keypoints;
}

// What `frames` says of image `im` (nothing known when `frames` is empty); an image that is not
// one of them is refused, naming `images_file`.
FrameInfo FrameOf(const ColmapImage& im, const FrameLookup& frames, const fs::path& images_file) {
  if (frames.empty()) return FrameInfo{};
  const auto it = frames.find(im.name);
  if (it == frames.end()) {
    throw map::MapError(images_file.string() + ": image '" + PrintableForMessage(im.name) + "' is not a frame of the recording");
  }
  return it->second;
}

// Image `im` as a keyframe, without its observations.
map::Keyframe KeyframeOf(const ColmapImage& im, const FrameInfo& info) {
  map::Keyframe kf;
  kf.colmap_image_id = im.id;
  kf.name = im.name;
  kf.frame_index = info.frame_index;
  kf.timestamp = info.timestamp;
  kf.pose = im.pose;
  return kf;
}

// The keyframes' order: by frame index, then name.
void SortByFrame(std::vector<ColmapImage>& images, const FrameLookup& frames, const fs::path& images_file) {
  std::sort(images.begin(), images.end(), [&](const ColmapImage& a, const ColmapImage& b) {
    const int fa = FrameOf(a, frames, images_file).frame_index, fb = FrameOf(b, frames, images_file).frame_index;
    return fa != fb ? fa < fb : a.name < b.name;
  });
}

}  // namespace

std::uint64_t CountRegisteredImages(const fs::path& sparse_dir) {
  BinaryReader r(sparse_dir / "images.bin", CancellationToken{});
  return r.Read<std::uint64_t>("registered image count");
}

std::vector<map::Keyframe> ReadColmapCameraPath(const fs::path& sparse_dir, const FrameLookup& frames) {
  const fs::path images_file = sparse_dir / "images.bin";
  std::vector<ColmapImage> images = ReadImages(images_file, CancellationToken{});
  SortByFrame(images, frames, images_file);
  std::vector<map::Keyframe> keyframes;
  for (const ColmapImage& im : images) keyframes.push_back(KeyframeOf(im, FrameOf(im, frames, images_file)));
  return keyframes;
}

std::vector<cv::Mat> ReadImageDescriptors(const fs::path& database, const std::vector<std::string>& names,
                                          const CancellationToken& cancel) {
  ColmapDatabase db(database, ColmapDatabase::Access::kRead);
  std::vector<cv::Mat> descriptors;
  descriptors.reserve(names.size());
  for (const std::string& name : names) {
    cancel.ThrowIfCancelled("reading the frames' descriptors");
    descriptors.push_back(db.Descriptors(db.ImageId(name)));
  }
  return descriptors;
}

CheckedModel ReadCheckedModel(const fs::path& sparse_dir, const fs::path& database, const FrameLookup& frames,
                              const CancellationToken& cancel) {
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  CheckedModel model;
  model.map = ReadColmapMap(sparse_dir, database, frames, cancel, &keypoints, false);
  model.check = CheckMap(model.map, keypoints, ReadTwoViewGeometries(database, model.map));
  return model;
}

std::vector<TwoViewGeometry> ReadTwoViewGeometries(const fs::path& database, const map::Map& map) {
  std::unordered_map<std::uint32_t, int> keyframe_of_image;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k)
    keyframe_of_image[map.keyframes[k].colmap_image_id] = static_cast<int>(k);
  ColmapDatabase db(database, ColmapDatabase::Access::kRead);
  std::vector<TwoViewGeometry> result;
  for (const auto& pair : db.PairGeometries()) {
    const auto a = keyframe_of_image.find(pair.image_a), b = keyframe_of_image.find(pair.image_b);
    if (a == keyframe_of_image.end() || b == keyframe_of_image.end()) continue;  // a frame not registered
    // Only pairs whose essential matrix COLMAP estimated and kept: CALIBRATED (2), and
    // PLANAR_OR_PANORAMIC (6: a homography fits as well). UNCALIBRATED (3) pairs fit a fundamental
    // matrix better than any essential one; their E is not the pair's motion (phone-fox: 8.7
    // degrees where the frames turned 57).
    if (pair.config != 2 && pair.config != 6) continue;
    result.push_back({a->second, b->second, pair.inliers, pair.essential, pair.matches});
  }
  return result;
}

DatabaseMatchGraph ReadMatchGraph(const fs::path& database) {
  ColmapDatabase db(database, ColmapDatabase::Access::kRead);
  DatabaseMatchGraph graph;
  for (auto& image : db.Images()) graph.images.emplace_back(image.id, std::move(image.name));
  graph.pairs = db.VerifiedPairs();
  return graph;
}

std::vector<FundamentalPair> ReadFundamentalMatrices(const fs::path& database) {
  ColmapDatabase db(database, ColmapDatabase::Access::kRead);
  std::vector<FundamentalPair> result;
  for (const auto& pair : db.PairGeometries()) {
    // CALIBRATED (2) and UNCALIBRATED (3) pairs: a general motion, whose F is defined (a
    // homography's pairs, planar or a pure turn, leave it free).
    if ((pair.config != 2 && pair.config != 3) || pair.fundamental.isZero()) continue;
    result.push_back({pair.image_a, pair.image_b, pair.inliers, pair.fundamental});
  }
  return result;
}

void SetSingleCameraParams(const fs::path& database, const std::vector<double>& params) {
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite).SetSingleCameraParams(params);
}

namespace {

// A model's three files read and checked each on its own and against each other's camera.
struct ModelFiles {
  std::vector<ColmapImage> images;
  std::vector<ColmapPoint> points;
  calib::Camera camera;
};

ModelFiles ReadModelFiles(const fs::path& sparse_dir, const CancellationToken& cancel) {
  const fs::path cameras_file = sparse_dir / "cameras.bin";
  const fs::path images_file = sparse_dir / "images.bin";
  const fs::path points_file = sparse_dir / "points3D.bin";
  const auto cameras = ReadCameras(cameras_file, cancel);
  ModelFiles model;
  model.images = ReadImages(images_file, cancel);
  model.points = ReadPoints(points_file, cancel);
  if (model.images.empty()) throw map::MapError(images_file.string() + ": the model has no registered images");
  if (model.points.empty()) throw map::MapError(points_file.string() + ": the model has no 3D points");
  model.camera = TheOneCamera(cameras, model.images, cameras_file, images_file);
  return model;
}

}  // namespace

SparseModel ReadSparseModel(const fs::path& sparse_dir, const CancellationToken& cancel) {
  ModelFiles files = ReadModelFiles(sparse_dir, cancel);
  const fs::path images_file = sparse_dir / "images.bin";
  std::unordered_map<std::uint32_t, std::uint32_t> index_of_image;
  for (const auto& im : files.images) {
    if (!index_of_image.emplace(im.id, static_cast<std::uint32_t>(index_of_image.size())).second) {
      throw map::MapError(images_file.string() + ": image id " + std::to_string(im.id) + " appears twice");
    }
  }
  RequireTracksReferBack(files.points, files.images, index_of_image, sparse_dir / "points3D.bin", images_file);
  SparseModel model;
  try {
    const fs::path cameras_file = sparse_dir / "cameras.bin";
    model.cameras_bin = NamingInput<map::MapError>(cameras_file.string(), [&] { return ReadFileUpTo(cameras_file, kMaxBinaryFileBytes, cancel); });
  } catch (const InputError& e) {
    throw map::MapError(e.what());
  }
  model.camera = files.camera;
  model.images = std::move(files.images);
  model.points = std::move(files.points);
  return model;
}

namespace {

map::Map ReadColmapModel(const fs::path& sparse_dir, const fs::path& database, const FrameLookup& frames,
                  const CancellationToken& cancel, std::vector<std::vector<Eigen::Vector2f>>* keypoints,
                  bool check_values) {
  const fs::path images_file = sparse_dir / "images.bin";
  const fs::path points_file = sparse_dir / "points3D.bin";
  ModelFiles files = ReadModelFiles(sparse_dir, cancel);
  auto& images = files.images;
  const auto& points = files.points;

  map::Map map;
  map.camera = files.camera;

  SortByFrame(images, frames, images_file);

  std::unordered_map<std::uint32_t, std::uint32_t> keyframe_of_image;
  for (const auto& im : images) {
    if (!keyframe_of_image.emplace(im.id, static_cast<std::uint32_t>(map.keyframes.size())).second) {
      throw map::MapError(images_file.string() + ": image id " + std::to_string(im.id) + " appears twice");
    }
    map.keyframes.push_back(KeyframeOf(im, FrameOf(im, frames, images_file)));
  }

  std::unordered_map<std::uint64_t, std::uint32_t> point_index;  // COLMAP id → index
  std::size_t rows = 0;
  for (const auto& p : points) {
    if (!point_index.emplace(p.id, static_cast<std::uint32_t>(point_index.size())).second) {
      throw map::MapError(points_file.string() + ": 3D point id " + std::to_string(p.id) + " appears twice");
    }
    rows += p.track.size();
  }
  if (rows > std::numeric_limits<std::uint32_t>::max()) throw map::MapError(points_file.string() + ": tracks too long");

  RequireTracksReferBack(points, images, keyframe_of_image, points_file, images_file);

  ColmapDatabase db(database, ColmapDatabase::Access::kRead);
  map.descriptors.create(static_cast<int>(rows), map::kDescriptorSize, CV_8UC1);
  map.descriptor_point.resize(rows);
  map.descriptor_keyframe.resize(rows);
  map.points.resize(points.size());
  std::unordered_map<std::uint64_t, std::uint32_t> row_of;  // (image, 2D index) → row
  row_of.reserve(rows);
  // Rows are filled image by image so that each image's descriptors are read once.
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> wanted(images.size());  // (2D idx, row)
  std::uint32_t row = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    map::MapPoint& mp = map.points[i];
    mp = points[i].point;
    mp.first_descriptor = row;
    mp.descriptor_count = static_cast<std::uint32_t>(points[i].track.size());
    for (const auto& e : points[i].track) {
      const std::uint32_t kf = keyframe_of_image.at(e.image_id);
      if (!row_of.emplace(Key(e.image_id, e.point2d_idx), row).second) {
        throw map::MapError(points_file.string() + ": 2D point " + std::to_string(e.point2d_idx) + " of image id " +
                       std::to_string(e.image_id) + " is in two tracks");
      }
      map.descriptor_point[row] = static_cast<std::uint32_t>(i);
      map.descriptor_keyframe[row] = kf;
      wanted[kf].push_back({e.point2d_idx, row});
      ++row;
    }
  }
  for (std::size_t k = 0; k < images.size(); ++k) {
    const auto& im = images[k];
    const std::string db_name = db.ImageName(im.id);
    if (db_name != im.name) {
      throw map::MapError(database.string() + ": image id " + std::to_string(im.id) + " is '" + PrintableForMessage(db_name) + "' but " +
                     images_file.string() + " calls it '" + PrintableForMessage(im.name) + "' (a different database?)");
    }
    const cv::Mat desc = db.Descriptors(im.id);
    if (static_cast<std::size_t>(desc.rows) != im.xy.size()) {
      throw map::MapError(database.string() + ": image '" + PrintableForMessage(im.name) + "' has " + std::to_string(desc.rows) +
                     " descriptors but " + std::to_string(im.xy.size()) + " 2D points in " + images_file.string());
    }
    for (const auto& [idx, r] : wanted[k]) desc.row(static_cast<int>(idx)).copyTo(map.descriptors.row(static_cast<int>(r)));

    map::Keyframe& kf = map.keyframes[k];
    for (std::uint32_t idx = 0; idx < im.point3d_ids.size(); ++idx) {
      const std::uint64_t pid = im.point3d_ids[idx];
      if (pid == kInvalidPoint3D) continue;
      const auto pi = point_index.find(pid);
      const auto ri = row_of.find(Key(im.id, idx));
      if (pi == point_index.end() || ri == row_of.end()) {
        throw map::MapError(images_file.string() + ": 2D point " + std::to_string(idx) + " of '" + PrintableForMessage(im.name) +
                       "' refers to 3D point " + std::to_string(pid) + ", whose track does not list it");
      }
      const Eigen::Vector2d px = im.xy[idx] - Eigen::Vector2d(0.5, 0.5);  // COLMAP → OpenCV pixels
      kf.observations.push_back({pi->second, px.cast<float>(), ri->second});
    }
  }
  if (keypoints) *keypoints = AllKeypoints(images);
  if (check_values) RequireModelValuesInRange(map, sparse_dir);
  return map;
}

}  // namespace

map::Map ReadColmapMap(const fs::path& sparse_dir, const fs::path& database, const FrameLookup& frames,
                  const CancellationToken& cancel, std::vector<std::vector<Eigen::Vector2f>>* keypoints,
                  bool check_values) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<map::MapError>(sparse_dir.string(), [&] {
    return ReadColmapModel(sparse_dir, database, frames, cancel, keypoints, check_values);
  });
}

void RequireReadableModel(const fs::path& sparse_dir, const CancellationToken& cancel) {
  NamingInput<map::MapError>(sparse_dir.string(), [&] { return ReadModelFiles(sparse_dir, cancel).images.size(); });
}

void RequireModelValuesInRange(const map::Map& map, const fs::path& sparse_dir) {
  const fs::path images_file = sparse_dir / "images.bin";
  const fs::path points_file = sparse_dir / "points3D.bin";
  for (const map::Keyframe& k : map.keyframes) {
    const double t = k.pose.t_cw.cwiseAbs().maxCoeff();
    if (t > map::kMaxCoordinate)
      throw map::MapError(images_file.string() + ": image " + std::to_string(k.colmap_image_id) + " ('" + PrintableForMessage(k.name) +
                          "') has a translation of " + Number(t) + ", beyond " + Number(map::kMaxCoordinate) +
                          " (a degenerate registration in COLMAP's model)");
    for (const map::KeyframeObservation& o : k.observations)
      if (o.pixel.cwiseAbs().maxCoeff() > map::kMaxPixel)
        throw map::MapError(images_file.string() + ": image " + std::to_string(k.colmap_image_id) + " ('" + PrintableForMessage(k.name) +
                            "') has a 2D point at (" + Number(o.pixel.x()) + ", " + Number(o.pixel.y()) +
                            "), beyond " + Number(map::kMaxPixel) + " pixels");
  }
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    const map::MapPoint& p = map.points[i];
    const double c = p.xyz.cwiseAbs().maxCoeff();
    if (c > map::kMaxCoordinate)
      throw map::MapError(points_file.string() + ": 3D point " + std::to_string(i + 1) + " of " +
                          std::to_string(map.points.size()) + " lies at a coordinate of " + Number(c) + ", beyond " +
                          Number(map::kMaxCoordinate) + " (a degenerate triangulation in COLMAP's model)");
    if (p.reprojection_error < 0 || p.reprojection_error > map::kMaxPixel)
      throw map::MapError(points_file.string() + ": 3D point " + std::to_string(i + 1) + " of " +
                          std::to_string(map.points.size()) + " has a reprojection error of " +
                          Number(p.reprojection_error) + " pixels");
  }
}

}  // namespace arview::mapping
