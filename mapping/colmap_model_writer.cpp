// Writing a COLMAP model, apart from reading one (mapping/colmap_model.cpp): the binary sparse
// model moved by a similarity (WriteTransformedModel, declared in mapping/colmap_model.h), each
// pose and point patched where it lies and every other byte kept as COLMAP wrote it. The metric
// step (mapping/map_folder.cpp) and `arview map extend` (mapping/map_extend.cpp) move models.
// WriteSparseModel writes a whole model held in memory (the leaves' merge, mapping/leaf_merge.h).

#include "mapping/colmap_model.h"

#include <algorithm>
#include <cstring>

#include "base/atomic_file.h"
#include "base/input_guard.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// A COLMAP binary file read whole, walked value by value, with values written over where they lie.
class BinaryPatch {
 public:
  explicit BinaryPatch(const fs::path& path) : path_(path) {
    try {
      data_ = ReadFileUpTo(path, kMaxBinaryFileBytes);
    } catch (const InputError& e) {
      throw map::MapError(e.what());
    }
  }
  std::size_t position() const { return pos_; }
  template <typename T>
  T Read() {
    Need(sizeof(T));
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  template <typename T>
  void WriteAt(std::size_t at, T value) {
    std::memcpy(data_.data() + at, &value, sizeof(T));
  }
  void Skip(std::uint64_t bytes) {
    Need(bytes);
    pos_ += static_cast<std::size_t>(bytes);
  }
  // `count` records of `size` bytes: a count no file can hold fails as truncated, before the
  // product could overflow.
  void SkipRecords(std::uint64_t count, std::size_t size) {
    if (count > (data_.size() - pos_) / size) Fail();
    Skip(count * size);
  }
  void SkipCString() {
    const auto end = std::find(data_.begin() + static_cast<std::ptrdiff_t>(pos_), data_.end(), '\0');
    if (end == data_.end()) Fail();
    pos_ = static_cast<std::size_t>(end - data_.begin()) + 1;
  }
  const std::string& bytes() const {
    if (pos_ != data_.size()) Fail();
    return data_;
  }

 private:
  void Need(std::uint64_t bytes) const {
    if (bytes > data_.size() - pos_) Fail();
  }
  [[noreturn]] void Fail() const { throw map::MapError(path_.string() + ": truncated or corrupted COLMAP model file"); }
  fs::path path_;
  std::string data_;
  std::size_t pos_ = 0;
};

// images.bin: per image its id, qvec (w x y z, world → camera), tvec, camera id, name, and its
// 2D points (x, y, point id).
std::string TransformedImages(const fs::path& file, const Sim3& transform) {
  BinaryPatch f(file);
  const auto images = f.Read<std::uint64_t>();
  for (std::uint64_t i = 0; i < images; ++i) {
    f.Read<std::uint32_t>();
    const std::size_t pose_at = f.position();
    double q[4], t[3];
    for (double& v : q) v = f.Read<double>();
    for (double& v : t) v = f.Read<double>();
    const Rigid3 moved = transform.TransformPose(
        Rigid3(Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(), Eigen::Vector3d(t[0], t[1], t[2])));
    const double out[7] = {moved.rotation.w(), moved.rotation.x(), moved.rotation.y(), moved.rotation.z(),
                           moved.translation.x(), moved.translation.y(), moved.translation.z()};
    for (int k = 0; k < 7; ++k) f.WriteAt(pose_at + k * sizeof(double), out[k]);
    f.Read<std::uint32_t>();
    f.SkipCString();
    f.SkipRecords(f.Read<std::uint64_t>(), 2 * sizeof(double) + sizeof(std::int64_t));
  }
  return f.bytes();
}

// points3D.bin: per point its id, xyz, rgb, error and track (image id, 2D point index).
std::string TransformedPoints(const fs::path& file, const Sim3& transform) {
  BinaryPatch f(file);
  const auto points = f.Read<std::uint64_t>();
  for (std::uint64_t i = 0; i < points; ++i) {
    f.Read<std::uint64_t>();
    const std::size_t xyz_at = f.position();
    Eigen::Vector3d xyz;
    for (int k = 0; k < 3; ++k) xyz[k] = f.Read<double>();
    const Eigen::Vector3d moved = transform(xyz);
    for (int k = 0; k < 3; ++k) f.WriteAt(xyz_at + k * sizeof(double), moved[k]);
    f.Skip(3 + sizeof(double));
    f.SkipRecords(f.Read<std::uint64_t>(), 2 * sizeof(std::uint32_t));
  }
  return f.bytes();
}

// Little-endian values appended as COLMAP's binary model files hold them.
class BinaryWriter {
 public:
  template <typename T>
  void Put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* bytes = reinterpret_cast<const char*>(&value);
    data_.append(bytes, sizeof(T));
  }
  void PutCString(const std::string& text) { data_.append(text.c_str(), text.size() + 1); }
  const std::string& bytes() const { return data_; }

 private:
  std::string data_;
};

std::string ImagesBin(const std::vector<ColmapImage>& images) {
  BinaryWriter w;
  w.Put<std::uint64_t>(images.size());
  for (const ColmapImage& im : images) {
    w.Put(im.id);
    const Eigen::Quaterniond& q = im.pose.q_cw;
    for (const double v : {q.w(), q.x(), q.y(), q.z()}) w.Put(v);
    for (int k = 0; k < 3; ++k) w.Put(im.pose.t_cw[k]);
    w.Put(im.camera_id);
    w.PutCString(im.name);
    w.Put<std::uint64_t>(im.xy.size());
    for (std::size_t k = 0; k < im.xy.size(); ++k) {
      w.Put(im.xy[k].x());
      w.Put(im.xy[k].y());
      w.Put(im.point3d_ids[k]);
    }
  }
  return w.bytes();
}

std::string PointsBin(const std::vector<ColmapPoint>& points) {
  BinaryWriter w;
  w.Put<std::uint64_t>(points.size());
  for (const ColmapPoint& p : points) {
    w.Put(p.id);
    for (int k = 0; k < 3; ++k) w.Put(p.point.xyz[k]);
    for (const std::uint8_t c : p.point.rgb) w.Put(c);
    w.Put(p.point.reprojection_error);
    w.Put<std::uint64_t>(p.track.size());
    for (const TrackElement& e : p.track) {
      w.Put(e.image_id);
      w.Put(e.point2d_idx);
    }
  }
  return w.bytes();
}

void WriteModelFiles(const fs::path& to, const std::string& cameras, const std::string& images, const std::string& points) {
  std::error_code ec;
  fs::create_directories(to, ec);
  if (ec) throw map::MapError(to.string() + ": cannot create the folder (" + ec.message() + ")");
  try {
    WriteFileAtomically(to / "cameras.bin", cameras);
    WriteFileAtomically(to / "images.bin", images);
    WriteFileAtomically(to / "points3D.bin", points);
  } catch (const Error& e) {
    throw map::MapError(e.what());
  }
}

}  // namespace

void WriteTransformedModel(const fs::path& from, const fs::path& to, const Sim3& transform) {
  const std::string images = TransformedImages(from / "images.bin", transform);
  const std::string points = TransformedPoints(from / "points3D.bin", transform);
  std::string cameras;
  try {
    cameras = ReadFileUpTo(from / "cameras.bin", kMaxBinaryFileBytes);
  } catch (const InputError& e) {
    throw map::MapError(e.what());
  }
  WriteModelFiles(to, cameras, images, points);
}

void WriteSparseModel(const SparseModel& model, const fs::path& to) {
  WriteModelFiles(to, model.cameras_bin, ImagesBin(model.images), PointsBin(model.points));
}

}  // namespace arview::mapping
