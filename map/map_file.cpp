#include "map/map_file.h"
#include "map/descriptor_size.h"

#include "base/atomic_file.h"
#include "base/point_spread.h"
#include "base/input_guard.h"
#include "base/library_errors.h"
#include "base/stats.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <type_traits>

namespace arview::map {

namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little, "the map file is written little-endian");

namespace {

constexpr char kMagic[8] = {'A', 'R', 'V', 'M', 'A', 'P', '\r', '\n'};
constexpr std::size_t kHeaderSize = 8 + 4 + 4 + 8 + 8;

std::uint64_t Checksum(const char* data, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, data + i, 8);
    h = (h ^ word) * kPrime;
    h ^= h >> 29;
  }
  for (; i < n; ++i) h = (h ^ static_cast<unsigned char>(data[i])) * kPrime;
  return h;
}

class Writer {
 public:
  template <typename T>
  void Put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&v);
    buf_.insert(buf_.end(), p, p + sizeof(T));
  }
  void PutBytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const char*>(p);
    buf_.insert(buf_.end(), c, c + n);
  }
  void PutString(const std::string& s) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    PutBytes(s.data(), s.size());
  }
  std::vector<char>& buffer() { return buf_; }

 private:
  std::vector<char> buf_;
};

class Reader {
 public:
  Reader(const char* data, std::size_t size, const fs::path& file) : data_(data), size_(size), file_(file) {}
  template <typename T>
  T Get(const char* what) {
    Need(sizeof(T), what);
    T v;
    std::memcpy(&v, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  void GetBytes(void* out, std::size_t n, const char* what) {
    Need(n, what);
    if (n > 0) std::memcpy(out, data_ + pos_, n);
    pos_ += n;
  }
  std::string GetString(const char* what) {
    const auto n = Get<std::uint32_t>(what);
    Need(n, what);
    std::string s(data_ + pos_, n);
    pos_ += n;
    return s;
  }
  // A count that must fit in the bytes left, `record` bytes per element.
  std::size_t GetCount(const char* what, std::size_t record) {
    const auto n = Get<std::uint64_t>(what);
    if (n > (size_ - pos_) / std::max<std::size_t>(record, 1)) Fail(std::string(what) + " exceeds the file size");
    return static_cast<std::size_t>(n);
  }
  bool AtEnd() const { return pos_ == size_; }
  [[noreturn]] void Fail(const std::string& problem) const {
    throw MapError(file_.string() + ": " + problem + " (corrupted map file)");
  }

 private:
  void Need(std::size_t n, const char* what) const {
    if (size_ - pos_ < n) Fail(std::string("truncated while reading ") + what);
  }
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  fs::path file_;
};

void WritePayload(const Map& map, Writer& w) {
  const calib::Camera& c = map.camera;
  w.Put<std::int32_t>(c.width);
  w.Put<std::int32_t>(c.height);
  for (double v : {c.fx, c.fy, c.cx, c.cy}) w.Put(v);
  for (double v : c.dist) w.Put(v);
  w.Put<std::uint8_t>(c.focus ? 1 : 0);
  w.Put<std::int64_t>(c.focus.value_or(0));

  w.Put<std::uint64_t>(map.keyframes.size());
  for (const Keyframe& k : map.keyframes) {
    w.Put(k.colmap_image_id);
    w.Put<std::int32_t>(k.frame_index);
    w.Put(k.timestamp);
    for (double v : {k.pose.q_cw.w(), k.pose.q_cw.x(), k.pose.q_cw.y(), k.pose.q_cw.z()}) w.Put(v);
    for (int i = 0; i < 3; ++i) w.Put(k.pose.t_cw[i]);
    w.PutString(k.name);
    w.Put<std::uint64_t>(k.observations.size());
    for (const KeyframeObservation& o : k.observations) {
      w.Put(o.point);
      w.Put(o.pixel.x());
      w.Put(o.pixel.y());
      w.Put(o.descriptor);
    }
  }

  w.Put<std::uint64_t>(map.points.size());
  for (const MapPoint& p : map.points) {
    for (int i = 0; i < 3; ++i) w.Put(p.xyz[i]);
    w.PutBytes(p.rgb.data(), 3);
    w.Put(p.reprojection_error);
    w.Put(p.first_descriptor);
    w.Put(p.descriptor_count);
  }

  const auto rows = static_cast<std::uint64_t>(map.descriptors.rows);
  w.Put(rows);
  for (int r = 0; r < map.descriptors.rows; ++r) w.PutBytes(map.descriptors.ptr(r), kDescriptorSize);
  w.PutBytes(map.descriptor_point.data(), map.descriptor_point.size() * sizeof(std::uint32_t));
  w.PutBytes(map.descriptor_keyframe.data(), map.descriptor_keyframe.size() * sizeof(std::uint32_t));

  const MapFrame& f = map.frame;
  w.Put(static_cast<std::uint8_t>(f.scale_source));
  w.Put<std::uint8_t>(f.z_up ? 1 : 0);
  w.Put(f.scale_error);
  w.PutString(f.how);
  w.Put(f.from_colmap.scale);
  for (int i = 0; i < 9; ++i) w.Put(f.from_colmap.R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) w.Put(f.from_colmap.t[i]);

  w.Put<std::uint64_t>(map.rooms.size());
  for (const std::string& room : map.rooms) w.PutString(room);
  for (const Keyframe& k : map.keyframes) w.Put<std::int32_t>(k.room);
}

void ReadFrame(Reader& r, MapFrame* f) {
  const auto source = r.Get<std::uint8_t>("map frame");
  if (source > static_cast<std::uint8_t>(ScaleSource::kCameraHeight)) r.Fail("unknown scale source " + std::to_string(source));
  f->scale_source = static_cast<ScaleSource>(source);
  const auto z_up = r.Get<std::uint8_t>("map frame");
  if (z_up > 1) r.Fail("z-up flag " + std::to_string(z_up));
  f->z_up = z_up == 1;
  f->scale_error = r.Get<double>("map frame");
  f->how = r.GetString("map frame");
  f->from_colmap.scale = r.Get<double>("map frame");
  for (int i = 0; i < 9; ++i) f->from_colmap.R(i / 3, i % 3) = r.Get<double>("map frame");
  for (int i = 0; i < 3; ++i) f->from_colmap.t[i] = r.Get<double>("map frame");
}

void ReadRooms(Reader& r, Map* map) {
  map->rooms.resize(r.GetCount("room count", 4));
  for (std::string& room : map->rooms) room = r.GetString("room name");
  for (Keyframe& k : map->keyframes) k.room = r.Get<std::int32_t>("keyframe room");
}

Map ReadPayload(Reader& r, std::uint32_t version) {
  Map map;
  calib::Camera& c = map.camera;
  c.width = r.Get<std::int32_t>("camera");
  c.height = r.Get<std::int32_t>("camera");
  c.fx = r.Get<double>("camera");
  c.fy = r.Get<double>("camera");
  c.cx = r.Get<double>("camera");
  c.cy = r.Get<double>("camera");
  for (double& d : c.dist) d = r.Get<double>("camera");
  if (version >= 2) {
    const auto has_focus = r.Get<std::uint8_t>("camera focus");
    const auto focus = r.Get<std::int64_t>("camera focus");
    if (has_focus > 1) r.Fail("camera focus flag " + std::to_string(has_focus));
    if (has_focus) c.focus = focus;
  }

  map.keyframes.resize(r.GetCount("keyframe count", 4 + 4 + 8 + 56 + 4 + 8));
  for (Keyframe& k : map.keyframes) {
    k.colmap_image_id = r.Get<std::uint32_t>("keyframe");
    k.frame_index = r.Get<std::int32_t>("keyframe");
    k.timestamp = r.Get<double>("keyframe");
    double q[4];
    for (double& v : q) v = r.Get<double>("keyframe pose");
    k.pose.q_cw = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    for (int i = 0; i < 3; ++i) k.pose.t_cw[i] = r.Get<double>("keyframe pose");
    k.name = r.GetString("keyframe name");
    k.observations.resize(r.GetCount("observation count", 16));
    for (KeyframeObservation& o : k.observations) {
      o.point = r.Get<std::uint32_t>("observation");
      o.pixel.x() = r.Get<float>("observation");
      o.pixel.y() = r.Get<float>("observation");
      o.descriptor = r.Get<std::uint32_t>("observation");
    }
  }

  map.points.resize(r.GetCount("point count", 24 + 3 + 8 + 8));
  for (MapPoint& p : map.points) {
    for (int i = 0; i < 3; ++i) p.xyz[i] = r.Get<double>("point");
    r.GetBytes(p.rgb.data(), 3, "point colour");
    p.reprojection_error = r.Get<double>("point");
    p.first_descriptor = r.Get<std::uint32_t>("point");
    p.descriptor_count = r.Get<std::uint32_t>("point");
  }

  const std::size_t rows = r.GetCount("descriptor count", kDescriptorSize + 8);
  map.descriptors.create(static_cast<int>(rows), kDescriptorSize, CV_8UC1);
  r.GetBytes(map.descriptors.data, rows * kDescriptorSize, "descriptors");
  map.descriptor_point.resize(rows);
  r.GetBytes(map.descriptor_point.data(), rows * sizeof(std::uint32_t), "descriptor points");
  map.descriptor_keyframe.resize(rows);
  r.GetBytes(map.descriptor_keyframe.data(), rows * sizeof(std::uint32_t), "descriptor keyframes");
  if (version >= 2) ReadFrame(r, &map.frame);
  if (version >= 3) ReadRooms(r, &map);
  if (!r.AtEnd()) r.Fail("unexpected bytes after the payload");
  return map;
}

}  // namespace


void ValidateMap(const Map& map, const std::string& source) {
  auto fail = [&](const std::string& problem) { throw MapError(source + ": " + problem); };
  try {
    map.camera.Validate(source + " (camera)");
  } catch (const calib::CameraError& e) {
    throw MapError(e.what());
  }
  const MapFrame& f = map.frame;
  if (!(f.scale_error >= 0 && f.scale_error < 10) || !(f.from_colmap.scale > 0 && f.from_colmap.scale < 1e12) ||
      !f.from_colmap.R.allFinite() || !f.from_colmap.t.allFinite() ||
      (f.from_colmap.R.transpose() * f.from_colmap.R - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    fail("the map's frame record is invalid (scale error, or a COLMAP-to-map transform that is not a similarity)");
  }
  const auto rows = static_cast<std::size_t>(map.descriptors.rows);
  if (rows > 0 && (map.descriptors.type() != CV_8UC1 || map.descriptors.cols != kDescriptorSize)) {
    fail("descriptors must be N x 128 CV_8U");
  }
  if (map.descriptor_point.size() != rows || map.descriptor_keyframe.size() != rows) {
    fail("descriptor_point / descriptor_keyframe sizes differ from the descriptor count");
  }
  for (const std::string& room : map.rooms) {
    if (room.empty() || room.find('\n') != std::string::npos) fail("a room's name is empty or holds a line break");
  }
  for (std::size_t i = 0; i < map.keyframes.size(); ++i) {
    const Keyframe& k = map.keyframes[i];
    if (k.room < -1 || k.room >= static_cast<int>(map.rooms.size())) {
      fail("keyframe " + std::to_string(i) + " ('" + k.name + "') names room " + std::to_string(k.room) + " of " +
           std::to_string(map.rooms.size()));
    }
    // Values far beyond any real scene (a corrupted file with its checksum recomputed) are
    // refused: the maths downstream would print nan or overflow.
    if (!std::isfinite(k.pose.q_cw.norm()) || std::abs(k.pose.q_cw.norm() - 1.0) > 1e-6 || !k.pose.t_cw.allFinite() ||
        k.pose.t_cw.cwiseAbs().maxCoeff() > kMaxCoordinate || !std::isfinite(k.timestamp)) {
      fail("keyframe " + std::to_string(i) + " ('" + k.name + "') has an invalid pose");
    }
    for (const KeyframeObservation& o : k.observations) {
      if (o.point >= map.points.size() || o.descriptor >= rows || !o.pixel.allFinite() ||
          o.pixel.cwiseAbs().maxCoeff() > kMaxPixel) {
        fail("keyframe " + std::to_string(i) + " has an observation with an index out of range");
      }
      if (map.descriptor_point[o.descriptor] != o.point || map.descriptor_keyframe[o.descriptor] != i) {
        fail("keyframe " + std::to_string(i) + " has an observation whose descriptor row belongs elsewhere");
      }
    }
  }
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    const MapPoint& p = map.points[i];
    if (!p.xyz.allFinite() || p.xyz.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      fail("point " + std::to_string(i) + " is not finite or lies beyond 1e6 map units");
    }
    if (!std::isfinite(p.reprojection_error) || p.reprojection_error < 0 || p.reprojection_error > kMaxPixel) {
      fail("point " + std::to_string(i) + " has an invalid reprojection error");
    }
    if (p.descriptor_count == 0 || p.first_descriptor > rows || p.descriptor_count > rows - p.first_descriptor) {
      fail("point " + std::to_string(i) + " has a descriptor range outside the descriptor rows");
    }
    for (std::uint32_t r = p.first_descriptor; r < p.first_descriptor + p.descriptor_count; ++r) {
      if (map.descriptor_point[r] != i) fail("descriptor row " + std::to_string(r) + " does not belong to its point");
    }
  }
  for (std::size_t r = 0; r < rows; ++r) {
    if (map.descriptor_keyframe[r] >= map.keyframes.size()) fail("descriptor row " + std::to_string(r) + " names no keyframe");
    // Every row lies in the range of the point it names (a row outside it was accepted before).
    const std::uint32_t owner = map.descriptor_point[r];
    if (owner >= map.points.size() || r < map.points[owner].first_descriptor ||
        r - map.points[owner].first_descriptor >= map.points[owner].descriptor_count) {
      fail("descriptor row " + std::to_string(r) + " lies outside the descriptor range of its point");
    }
  }
}

void SaveMap(const Map& map, const fs::path& file) {
  ValidateMap(map, "map to save as " + file.string());
  Writer payload;
  WritePayload(map, payload);
  const std::vector<char>& body = payload.buffer();
  Writer header;
  header.PutBytes(kMagic, sizeof kMagic);
  header.Put<std::uint32_t>(kMapFileVersion);
  header.Put<std::uint32_t>(0);
  header.Put<std::uint64_t>(body.size());
  header.Put<std::uint64_t>(Checksum(body.data(), body.size()));

  std::string bytes(header.buffer().begin(), header.buffer().end());
  bytes.append(body.data(), body.size());
  WriteFileAtomically(file, bytes);
}

namespace {

Map LoadMapFile(const fs::path& path) {
  std::error_code ec;
  const fs::path file = fs::is_directory(path, ec) ? path / kMapFileName : path;
  if (!fs::exists(file, ec)) throw MapError(file.string() + ": map file missing (run 'arview map' first)");
  // Only a regular file, read whole: a FIFO would block for ever, a link to /dev/zero would read
  // as an empty map, and a file cut short while it is read (a copy still under way) is refused.
  std::string data;
  try {
    data = ReadFileUpTo(file, kMaxBinaryFileBytes);
  } catch (const InputError& e) {
    throw MapError(std::string(e.what()) + " (map file)");
  }
  const std::size_t size = data.size();

  Reader header(data.data(), std::min(size, kHeaderSize), file);
  char magic[8];
  header.GetBytes(magic, 8, "header");
  if (std::memcmp(magic, kMagic, 8) != 0) throw MapError(file.string() + ": not an arview map file");
  const auto version = header.Get<std::uint32_t>("header");
  if (version < 1 || version > kMapFileVersion) {
    throw MapError(file.string() + ": map file version " + std::to_string(version) + ", this arview reads versions 1 to " +
                   std::to_string(kMapFileVersion) + " (rebuild the map with 'arview map')");
  }
  header.Get<std::uint32_t>("header");
  const auto payload_size = header.Get<std::uint64_t>("header");
  const auto checksum = header.Get<std::uint64_t>("header");
  if (payload_size != size - kHeaderSize) {
    throw MapError(file.string() + ": truncated or padded: the header announces " + std::to_string(payload_size) +
                   " payload bytes, the file has " + std::to_string(size - kHeaderSize));
  }
  if (Checksum(data.data() + kHeaderSize, payload_size) != checksum) {
    throw MapError(file.string() + ": checksum mismatch (corrupted map file)");
  }
  Reader body(data.data() + kHeaderSize, payload_size, file);
  Map map = ReadPayload(body, version);
  ValidateMap(map, file.string());
  return map;
}

}  // namespace

Map LoadMap(const fs::path& path) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<MapError>(path.string(), [&] { return LoadMapFile(path); });
}

const char* ToString(ScaleSource source) {
  switch (source) {
    case ScaleSource::kNone: return "none";
    case ScaleSource::kBoard: return "board";
    case ScaleSource::kKnownDistance: return "known distance";
    case ScaleSource::kCameraHeight: return "camera height";
  }
  return "unknown";
}

std::optional<std::string> DegeneratePoints(const Map& map) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(map.points.size());
  for (const MapPoint& p : map.points) points.push_back(p.xyz);
  return WhyNotAPlane(points, "points");
}

int RoomAt(const Map& map, const Eigen::Vector3d& centre) {
  int room = -1;
  if (map.rooms.empty()) return room;
  double nearest = std::numeric_limits<double>::infinity();
  for (const Keyframe& k : map.keyframes) {
    const double d = (k.pose.Center() - centre).squaredNorm();
    if (k.room >= 0 && d < nearest) {
      nearest = d;
      room = k.room;
    }
  }
  return room;
}

MapStats ComputeStats(const Map& map) {
  MapStats s;
  s.keyframes = map.keyframes.size();
  s.points = map.points.size();
  s.descriptors = static_cast<std::size_t>(map.descriptors.rows);
  std::vector<double> errors;
  for (const Keyframe& k : map.keyframes) {
    for (const KeyframeObservation& o : k.observations) {
      const Eigen::Vector3d pc = k.pose.ToCamera(map.points[o.point].xyz);
      if (pc.z() <= 0) continue;
      errors.push_back((map.camera.Project(pc) - o.pixel.cast<double>()).norm());
    }
  }
  s.observations = errors.size();
  if (!map.points.empty()) {
    double tracks = 0, colmap_error = 0;
    for (const MapPoint& p : map.points) {
      tracks += p.descriptor_count;
      colmap_error += p.reprojection_error;
    }
    s.mean_track_length = tracks / static_cast<double>(map.points.size());
    s.mean_colmap_point_error = colmap_error / static_cast<double>(map.points.size());
  }
  s.mean_reprojection_error = Mean(errors);
  s.median_reprojection_error = Median(errors);
  return s;
}

}  // namespace arview::map
