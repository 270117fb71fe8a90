#include "room/room_light.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <system_error>
#include <vector>

#include "base/atomic_file.h"
#include "base/input_guard.h"
#include "base/library_errors.h"
#include "base/opencv_matrix.h"

namespace arview::room {
namespace {

// Our writer nests 5 levels (thumbnails, a thumbnail, its image matrix, the data list); a
// little room for hand edits, far below what overflows OpenCV's recursive reader.
constexpr int kMaxRoomLightDepth = 8;

// Equirectangular map of directions: column = azimuth, row = polar angle from +z.
struct DirectionMap {
  int width, height;
  std::vector<Eigen::Vector3d> sum;
  std::vector<int> count;
  DirectionMap(int w) : width(w), height(w / 2), sum(w * (w / 2), Eigen::Vector3d::Zero()), count(w * (w / 2), 0) {}
  int Index(const Eigen::Vector3d& d) const {
    const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
    double phi = std::atan2(d.y(), d.x());
    if (phi < 0) phi += 2 * M_PI;
    const int col = std::min(width - 1, static_cast<int>(phi / (2 * M_PI) * width));
    const int row = std::min(height - 1, static_cast<int>(theta / M_PI * height));
    return row * width + col;
  }
  Eigen::Vector3d Direction(int row, int col) const {
    const double theta = (row + 0.5) * M_PI / height, phi = (col + 0.5) * 2 * M_PI / width;
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
  }
  double SolidAngle(int row) const {
    // Exact area of the texel's band slice.
    const double t0 = row * M_PI / height, t1 = (row + 1) * M_PI / height;
    return (2 * M_PI / width) * (std::cos(t0) - std::cos(t1));
  }
};

// Fills texels no sample reached with the mean of their filled 4-neighbours (longitude wraps),
// ring by ring, so each hole takes the value of the nearest seen directions.
void FillHoles(DirectionMap& map, std::vector<Eigen::Vector3d>& value, std::vector<bool>& filled) {
  for (int pass = 0; pass < map.width + map.height; ++pass) {
    std::vector<std::pair<int, Eigen::Vector3d>> updates;
    for (int r = 0; r < map.height; ++r)
      for (int c = 0; c < map.width; ++c) {
        const int i = r * map.width + c;
        if (filled[i]) continue;
        Eigen::Vector3d acc = Eigen::Vector3d::Zero();
        int n = 0;
        const int neighbours[4][2] = {{r - 1, c}, {r + 1, c}, {r, (c + 1) % map.width}, {r, (c + map.width - 1) % map.width}};
        for (const auto& nb : neighbours) {
          if (nb[0] < 0 || nb[0] >= map.height) continue;
          const int j = nb[0] * map.width + nb[1];
          if (filled[j]) acc += value[j], ++n;
        }
        if (n > 0) updates.emplace_back(i, acc / n);
      }
    if (updates.empty()) return;
    for (const auto& [i, v] : updates) value[i] = v, filled[i] = true;
  }
}

Eigen::Vector3d PixelRgb(const cv::Mat& image, int y, int x) {
  if (image.depth() == CV_32F) {
    const cv::Vec3f p = image.at<cv::Vec3f>(y, x);
    return {p[2], p[1], p[0]};
  }
  const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
  return Eigen::Vector3d(p[2], p[1], p[0]) / 255.0;
}

cv::Mat AsColour(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw LightError(what + ": empty image");
  if (image.depth() == CV_32F && image.channels() == 3) return image;
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw LightError(what + ": expected an 8-bit BGR or grey image (or linear CV_32FC3)");
  }
  if (image.channels() == 3) return image;
  cv::Mat bgr;
  cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

void WritePose(cv::FileStorage& fs, const calib::Pose& pose) {
  const Eigen::Quaterniond q = pose.q_cw.normalized();
  fs << "[" << q.w() << q.x() << q.y() << q.z() << pose.t_cw.x() << pose.t_cw.y() << pose.t_cw.z() << "]";
}

}  // namespace

namespace {

// LinearThumbnail of an 8-bit BGR image whose sides are whole multiples of the thumbnail's, in
// one pass: each block's mean (rounded to 8 bits, as cv::resize's area average) and its largest
// channel value. The exposure follower makes one of these every 4th frame; cv::resize (0.49 ms
// for 640x480 → 40x30) plus the clipping mask (inRange and its own resize, 0.35 ms) took 0.84 ms
// of thread CPU on this machine.
cv::Mat BlockThumbnail(const cv::Mat& image, int width, int height) {
  const int bw = image.cols / width, bh = image.rows / height, area = bw * bh;
  cv::Mat linear(height, width, CV_32FC3);
  std::vector<int> sum(3 * static_cast<size_t>(width));
  std::vector<std::uint8_t> top(width);
  for (int by = 0; by < height; ++by) {
    std::fill(sum.begin(), sum.end(), 0);
    std::fill(top.begin(), top.end(), 0);
    for (int y = by * bh; y < (by + 1) * bh; ++y) {
      const std::uint8_t* p = image.ptr<std::uint8_t>(y);
      for (int bx = 0; bx < width; ++bx) {
        int b = 0, g = 0, r = 0, most = 0;
        for (int x = 0; x < bw; ++x, p += 3) {
          b += p[0], g += p[1], r += p[2];
          most = std::max(most, std::max<int>(p[0], std::max(p[1], p[2])));
        }
        sum[3 * bx] += b, sum[3 * bx + 1] += g, sum[3 * bx + 2] += r;
        top[bx] = static_cast<std::uint8_t>(std::max<int>(top[bx], most));
      }
    }
    cv::Vec3f* out = linear.ptr<cv::Vec3f>(by);
    for (int bx = 0; bx < width; ++bx) {
      for (int c = 0; c < 3; ++c) out[bx][c] = static_cast<float>((sum[3 * bx + c] + area / 2) / area) / 255.f;
      if (top[bx] >= kClippedLevel) out[bx] = cv::Vec3f::all(kClippedThumbnail);
    }
  }
  return linear;
}

}  // namespace

cv::Mat LinearThumbnail(const cv::Mat& image_in, int width) {
  const cv::Mat image = AsColour(image_in, "thumbnail");
  const int height = std::max(1, static_cast<int>(std::lround(width * double(image.rows) / image.cols)));
  if (image.depth() == CV_8U && image.cols % width == 0 && image.rows % height == 0) {
    return BlockThumbnail(image, width, height);
  }
  cv::Mat small, linear;
  cv::resize(image, small, {width, height}, 0, 0, cv::INTER_AREA);
  small.convertTo(linear, CV_32FC3, image.depth() == CV_8U ? 1.0 / 255 : 1.0);
  if (image.depth() == CV_8U) {
    // A thumbnail pixel with any clipped camera pixel under it under-reads: marked unusable
    // (every channel at kClippedThumbnail), so the exposure ratio leaves it out.
    cv::Mat clipped, any, share;
    cv::inRange(image, cv::Scalar::all(0), cv::Scalar::all(kClippedLevel - 1), clipped);  // 255: no channel clipped
    cv::resize(clipped, share, {width, height}, 0, 0, cv::INTER_AREA);
    linear.setTo(cv::Scalar::all(kClippedThumbnail), share < 255);
  }
  return linear;
}

RoomLight EstimateRoomLight(std::span<const LightKeyframe> keyframes, const TriangleBvh& scene,
                            const Eigen::Vector3d& position, const LightEstimateOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (keyframes.empty()) throw LightError("light estimate: no keyframes");
  if (options.environment_width < 8 || options.sample_width < 8) throw LightError("light estimate: maps too small");
  DirectionMap map(options.environment_width);
  RoomLight light;
  light.position = position;
  const Eigen::Vector3f p = position.cast<float>();
  for (size_t k = 0; k < keyframes.size(); ++k) {
    const LightKeyframe& key = keyframes[k];
    const std::string what = "keyframe " + std::to_string(k);
    const cv::Mat image = AsColour(key.image, what);
    if (image.cols != key.camera.width || image.rows != key.camera.height) {
      throw LightError(what + ": image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                       ", its camera " + std::to_string(key.camera.width) + "x" + std::to_string(key.camera.height));
    }
    const double step = double(image.cols) / options.sample_width;
    const int sw = options.sample_width, sh = std::max(1, static_cast<int>(image.rows / step));
    cv::Mat small;
    cv::resize(image, small, {sw, sh}, 0, 0, cv::INTER_AREA);
    // The small image's pixel centres in the full image, undistorted to normalised rays.
    std::vector<cv::Point2f> pixels, rays;
    for (int y = 0; y < sh; ++y)
      for (int x = 0; x < sw; ++x) pixels.emplace_back(float((x + 0.5) * step - 0.5), float((y + 0.5) * step - 0.5));
    cv::undistortPoints(pixels, rays, key.camera.K(), key.camera.DistCoeffs());
    const Eigen::Matrix3d r_wc = key.pose.CameraToWorldRotation().toRotationMatrix();
    const Eigen::Vector3f centre = key.pose.Center().cast<float>();
    for (int y = 0; y < sh; ++y)
      for (int x = 0; x < sw; ++x) {
        const cv::Point2f& ray = rays[y * sw + x];
        const Eigen::Vector3f dir = (r_wc * Eigen::Vector3d(ray.x, ray.y, 1).normalized()).cast<float>();
        const RayHit hit = scene.Nearest(centre, dir, 1e-4f, 1e30f);
        Eigen::Vector3d from_character = dir.cast<double>();
        if (hit.triangle >= 0) {
          const Eigen::Vector3f to_point = centre + hit.distance * dir - p;
          if (to_point.norm() < 1e-6f) continue;
          from_character = to_point.normalized().cast<double>();
        }
        const int i = map.Index(from_character);
        map.sum[i] += PixelRgb(small, y, x);
        ++map.count[i];
      }
    light.thumbnails.push_back({key.pose, LinearThumbnail(image, options.thumbnail_width),
                                {key.camera.fx, key.camera.fy, key.camera.cx, key.camera.cy}, image.size()});
  }
  std::vector<Eigen::Vector3d> value(map.sum.size(), Eigen::Vector3d::Zero());
  std::vector<bool> filled(map.sum.size(), false);
  double seen = 0;
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const int i = r * map.width + c;
      if (map.count[i] == 0) continue;
      value[i] = map.sum[i] / map.count[i];
      filled[i] = true;
      seen += map.SolidAngle(r);
    }
  if (seen == 0) throw LightError("light estimate: no keyframe pixel gave a direction");
  FillHoles(map, value, filled);
  light.sh.fill(Eigen::Vector3d::Zero());
  for (int r = 0; r < map.height; ++r) {
    const double area = map.SolidAngle(r);
    for (int c = 0; c < map.width; ++c) {
      const Sh9 y = ShBasis(map.Direction(r, c));
      for (int k = 0; k < 9; ++k) light.sh[k] += value[r * map.width + c] * (y[k] * area);
    }
  }
  light.dominant = ExtractDominantLight(light.sh);
  light.seen_fraction = seen / (4 * M_PI);
  light.keyframes = static_cast<int>(keyframes.size());
  light.scene_triangles = scene.vertices();
  light.occluder_triangles = scene.vertices();
  light.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return light;
}

void SaveRoomLight(const RoomLight& light, const std::filesystem::path& file) {
  std::string text;
  {
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    if (!fs.isOpened()) throw LightError(file.string() + ": cannot write");
    fs << "format" << "arview room light 1";
    fs << "position" << "[" << light.position.x() << light.position.y() << light.position.z() << "]";
    cv::Mat sh(9, 3, CV_64F);
    for (int k = 0; k < 9; ++k)
      for (int c = 0; c < 3; ++c) sh.at<double>(k, c) = light.sh[k][c];
    fs << "sh_rgb" << sh;
    const DominantLight& d = light.dominant;
    fs << "dominant_direction" << "[" << d.direction.x() << d.direction.y() << d.direction.z() << "]";
    fs << "dominant_color" << "[" << d.color.x() << d.color.y() << d.color.z() << "]";
    fs << "ambient" << "[" << d.ambient.x() << d.ambient.y() << d.ambient.z() << "]";
    fs << "seen_fraction" << light.seen_fraction << "keyframes" << light.keyframes << "seconds" << light.seconds;
    fs << "thumbnails" << "[";
    for (const KeyframeThumbnail& t : light.thumbnails) {
      fs << "{" << "pose";
      WritePose(fs, t.pose);
      fs << "intrinsics" << "[" << t.intrinsics[0] << t.intrinsics[1] << t.intrinsics[2] << t.intrinsics[3] << "]";
      fs << "image_size" << "[" << t.image_size.width << t.image_size.height << "]";
      fs << "image" << t.linear_bgr << "}";
    }
    fs << "]";
    auto write_triangles = [&](const char* key, const std::vector<Eigen::Vector3f>& corners) {
      cv::Mat tris(static_cast<int>(corners.size()), 3, CV_32F);
      for (int i = 0; i < tris.rows; ++i)
        for (int c = 0; c < 3; ++c) tris.at<float>(i, c) = corners[i][c];
      fs << key << tris;
    };
    write_triangles("scene_vertices", light.scene_triangles);
    write_triangles("occluder_vertices", light.occluder_triangles);
    text = fs.releaseAndGetString();
  }
  try {
    WriteFileAtomically(file, text);
  } catch (const std::exception& e) {
    throw LightError(e.what());
  }
}

namespace {

RoomLight LoadRoomLightFile(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) throw LightError(file.string() + ": no such room light file");
  // A regular file of bounded size, and the checks OpenCV's reader lacks, before it sees it.
  std::string text;
  try {
    text = ReadFileUpTo(file, kMaxTextFileBytes);
    RequireOpenCvYamlShape(text, kMaxRoomLightDepth, file.string());
  } catch (const InputError& e) {
    throw LightError(e.what());
  }
  RoomLight light;
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw LightError(file.string() + ": cannot read");
    if (static_cast<std::string>(fs["format"]) != "arview room light 1") {
      throw LightError(file.string() + ": not an arview room light file (format line missing)");
    }
    auto vec3 = [&](const char* key) {
      const cv::FileNode n = fs[key];
      if (!n.isSeq() || n.size() != 3) throw LightError(file.string() + ": " + key + " must be 3 numbers");
      Eigen::Vector3d v(n[0].real(), n[1].real(), n[2].real());
      if (!v.allFinite()) throw LightError(file.string() + ": " + key + " is not finite");
      return v;
    };
    light.position = vec3("position");
    cv::Mat sh;
    ReadOpenCvMatrix(fs["sh_rgb"], sh, file.string() + ": sh_rgb");
    if (sh.rows != 9 || sh.cols != 3 || sh.type() != CV_64F || !cv::checkRange(sh)) {
      throw LightError(file.string() + ": sh_rgb must be a finite 9x3 matrix");
    }
    for (int k = 0; k < 9; ++k) light.sh[k] = {sh.at<double>(k, 0), sh.at<double>(k, 1), sh.at<double>(k, 2)};
    light.dominant.direction = vec3("dominant_direction").normalized();
    light.dominant.color = vec3("dominant_color");
    light.dominant.ambient = vec3("ambient");
    light.seen_fraction = static_cast<double>(fs["seen_fraction"]);
    light.keyframes = static_cast<int>(fs["keyframes"]);
    light.seconds = static_cast<double>(fs["seconds"]);
    for (const cv::FileNode& t : fs["thumbnails"]) {
      const cv::FileNode pose = t["pose"];
      if (!pose.isSeq() || pose.size() != 7) throw LightError(file.string() + ": a thumbnail pose must be 7 numbers");
      KeyframeThumbnail thumb;
      thumb.pose.q_cw = Eigen::Quaterniond(pose[0].real(), pose[1].real(), pose[2].real(), pose[3].real()).normalized();
      thumb.pose.t_cw = {pose[4].real(), pose[5].real(), pose[6].real()};
      const cv::FileNode k = t["intrinsics"], size = t["image_size"];
      if (!k.isSeq() || k.size() != 4 || !size.isSeq() || size.size() != 2) {
        throw LightError(file.string() + ": a thumbnail needs intrinsics (4 numbers) and image_size (2)");
      }
      thumb.intrinsics = {k[0].real(), k[1].real(), k[2].real(), k[3].real()};
      thumb.image_size = {static_cast<int>(size[0]), static_cast<int>(size[1])};
      if (!thumb.intrinsics.allFinite() || thumb.intrinsics[0] <= 0 || thumb.intrinsics[1] <= 0 ||
          thumb.image_size.width <= 0 || thumb.image_size.height <= 0) {
        throw LightError(file.string() + ": a thumbnail's camera is not valid");
      }
      ReadOpenCvMatrix(t["image"], thumb.linear_bgr, file.string() + ": a thumbnail's image");
      if (thumb.linear_bgr.type() != CV_32FC3 || thumb.linear_bgr.empty()) {
        throw LightError(file.string() + ": a thumbnail image is not a float BGR image");
      }
      light.thumbnails.push_back(std::move(thumb));
    }
    auto read_triangles = [&](const char* key, std::vector<Eigen::Vector3f>& corners) {
      cv::Mat tris;
      ReadOpenCvMatrix(fs[key], tris, file.string() + ": " + key);
      if (!tris.empty() && (tris.cols != 3 || tris.type() != CV_32F || tris.rows % 3 != 0 || !cv::checkRange(tris))) {
        throw LightError(file.string() + ": " + key + " must be finite rows of 3 floats, 3 rows a triangle");
      }
      for (int i = 0; i < tris.rows; ++i) corners.emplace_back(tris.at<float>(i, 0), tris.at<float>(i, 1), tris.at<float>(i, 2));
    };
    read_triangles("scene_vertices", light.scene_triangles);
    read_triangles("occluder_vertices", light.occluder_triangles);
  } catch (const InputError& e) {
    throw LightError(e.what());
  } catch (const cv::Exception& e) {
    throw LightError(file.string() + ": unreadable room light file (" + e.msg + ")");
  }
  return light;
}

}  // namespace

RoomLight LoadRoomLight(const std::filesystem::path& file) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<LightError>(file.string(), [&] { return LoadRoomLightFile(file); });
}

ExposureFollower::ExposureFollower(std::vector<KeyframeThumbnail> thumbnails,
                                   const std::vector<Eigen::Vector3f>& scene_triangles, const calib::Camera& live_camera,
                                   double smoothing)
    : thumbnails_(std::move(thumbnails)), live_camera_(live_camera), smoothing_(std::clamp(smoothing, 1e-3, 1.0)) {
  if (!scene_triangles.empty()) scene_ = std::make_unique<TriangleBvh>(scene_triangles);
  if (thumbnails_.size() > 1) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& t : thumbnails_) mean += t.pose.Center();
    mean /= static_cast<double>(thumbnails_.size());
    double spread = 0;
    for (const auto& t : thumbnails_) spread += (t.pose.Center() - mean).squaredNorm();
    centre_spread_ = std::max(1e-9, std::sqrt(spread / thumbnails_.size()));
  }
}

namespace {

bool Clipped(const cv::Vec3f& p) { return p[0] >= kClippedThumbnail || p[1] >= kClippedThumbnail || p[2] >= kClippedThumbnail; }

// Bilinear sample of a thumbnail at full-image pixel (u, v); false when outside or next to a clipped pixel.
bool SampleThumbnail(const KeyframeThumbnail& key, double u, double v, Eigen::Vector3d* rgb) {
  const cv::Mat& t = key.linear_bgr;
  const double x = (u + 0.5) * t.cols / key.image_size.width - 0.5, y = (v + 0.5) * t.rows / key.image_size.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= t.cols || y0 + 1 >= t.rows) return false;
  const double fx = x - x0, fy = y - y0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const cv::Vec3f p = t.at<cv::Vec3f>(y0 + dy, x0 + dx);
      if (Clipped(p)) return false;
      sum += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * Eigen::Vector3d(p[2], p[1], p[0]);
    }
  *rgb = sum;
  return true;
}

}  // namespace

bool ExposureFollower::Compare(const cv::Mat& now, const calib::Pose& pose, const KeyframeThumbnail& key,
                               Eigen::Vector3d* live_sum, Eigen::Vector3d* key_sum) const {
  *live_sum = *key_sum = Eigen::Vector3d::Zero();
  int used = 0;
  const Eigen::Matrix3d r_wc = pose.CameraToWorldRotation().toRotationMatrix();
  const Eigen::Vector3f centre = pose.Center().cast<float>();
  const Eigen::Vector3f key_centre = key.pose.Center().cast<float>();
  for (int y = 0; y < now.rows; ++y)
    for (int x = 0; x < now.cols; ++x) {
      const cv::Vec3f a = now.at<cv::Vec3f>(y, x);
      if (Clipped(a)) continue;
      Eigen::Vector3d b;
      if (scene_) {
        // The scene point this live pixel sees, where the keyframe saw it.
        const double u = (x + 0.5) * live_camera_.width / now.cols - 0.5, v = (y + 0.5) * live_camera_.height / now.rows - 0.5;
        const Eigen::Vector3f dir =
            (r_wc * Eigen::Vector3d((u - live_camera_.cx) / live_camera_.fx, (v - live_camera_.cy) / live_camera_.fy, 1)
                        .normalized())
                .cast<float>();
        const RayHit hit = scene_->Nearest(centre, dir, 1e-4f, 1e30f);
        if (hit.triangle < 0) continue;
        const Eigen::Vector3f point = centre + hit.distance * dir;
        const Eigen::Vector3d in_key = key.pose.ToCamera(point.cast<double>());
        if (in_key.z() <= 0) continue;
        const Eigen::Vector3f back = point - key_centre;
        const float distance = back.norm();
        const RayHit block = scene_->Nearest(key_centre, back / distance, 1e-4f, 0.99f * distance);
        if (block.triangle >= 0) continue;  // the keyframe did not see this point
        const double ku = key.intrinsics[0] * in_key.x() / in_key.z() + key.intrinsics[2];
        const double kv = key.intrinsics[1] * in_key.y() / in_key.z() + key.intrinsics[3];
        if (!SampleThumbnail(key, ku, kv, &b)) continue;
      } else {
        if (y >= key.linear_bgr.rows || x >= key.linear_bgr.cols) continue;
        const cv::Vec3f p = key.linear_bgr.at<cv::Vec3f>(y, x);
        if (Clipped(p)) continue;
        b = {p[2], p[1], p[0]};
      }
      *live_sum += Eigen::Vector3d(a[2], a[1], a[0]);
      *key_sum += b;
      ++used;
    }
  return used >= 30 && (key_sum->array() > 1e-3).all() && (live_sum->array() > 1e-3).all();
}

Eigen::Vector3d ExposureFollower::Update(const cv::Mat& live, const calib::Pose& pose) {
  if (thumbnails_.empty() || live.empty()) return gain_;
  // The keyframe that looked most nearly the same way from nearby.
  const Eigen::Vector3d axis = pose.CameraToWorldRotation() * Eigen::Vector3d::UnitZ();
  double best_score = 1e300;
  int best = 0;
  for (size_t i = 0; i < thumbnails_.size(); ++i) {
    const calib::Pose& k = thumbnails_[i].pose;
    const double cos_angle = axis.dot(k.CameraToWorldRotation() * Eigen::Vector3d::UnitZ());
    const double score = (1 - cos_angle) + 0.1 * (k.Center() - pose.Center()).norm() / centre_spread_;
    if (score < best_score) best_score = score, best = static_cast<int>(i);
  }
  last_keyframe_ = best;
  const KeyframeThumbnail& key = thumbnails_[best];
  const cv::Mat now = LinearThumbnail(live, key.linear_bgr.cols);
  Eigen::Vector3d live_sum, key_sum;
  if (!Compare(now, pose, key, &live_sum, &key_sum)) return gain_;
  const Eigen::Vector3d measured = live_sum.cwiseQuotient(key_sum);
  if (!started_) {
    gain_ = measured;
    started_ = true;
  } else {
    for (int c = 0; c < 3; ++c) gain_[c] = std::exp(std::log(gain_[c]) + smoothing_ * (std::log(measured[c]) - std::log(gain_[c])));
  }
  return gain_;
}

}  // namespace arview::room
