#include "mapping/metric_frame.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <unordered_map>

#include "base/stats.h"
#include "calib/calibration.h"
#include "mapping/floor_search.h"

namespace arview::mapping {
namespace {

constexpr double kDeg = M_PI / 180;
// A sighting whose corners reproject this far (RMS) from the corners triangulated without it is a
// wrong detection or a keyframe posed wrongly; the board's corners are found to a tenth of that.
constexpr double kSightingAgreementPx = 3.0;
constexpr double kMinWidestAngleDeg = 3.0;

// Direction of a pixel's ray in the camera frame (unit), through the map's camera model.
Eigen::Vector3d Ray(const calib::Camera& camera, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d n = camera.PixelToNormalized(pixel);
  return Eigen::Vector3d(n.x(), n.y(), 1).normalized();
}

// Linear triangulation (DLT) from rays in several posed cameras: the point minimising the sum of
// squared cross products, in the map's frame.
Eigen::Vector3d TriangulateRays(const std::vector<calib::Pose>& poses, const std::vector<Eigen::Vector3d>& rays) {
  Eigen::MatrixXd a(2 * poses.size(), 4);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    Eigen::Matrix<double, 3, 4> p;
    p << poses[i].R(), poses[i].t_cw;
    const Eigen::Vector3d& r = rays[i];
    a.row(2 * i) = r.x() * p.row(2) - r.z() * p.row(0);
    a.row(2 * i + 1) = r.y() * p.row(2) - r.z() * p.row(1);
  }
  const Eigen::Vector4d h = Eigen::JacobiSVD<Eigen::MatrixXd>(a, Eigen::ComputeFullV).matrixV().col(3);
  return h.head<3>() / h.w();
}

double ReprojectionPx(const calib::Camera& camera, const calib::Pose& pose, const Eigen::Vector3d& x,
                      const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d c = pose.ToCamera(x);
  if (c.z() <= 0) return 1e9;  // behind the camera: as far off as it gets
  return (camera.Project(c) - pixel).norm();
}

// The four orders in which a chessboard's corners can be listed: from any of its corners, along
// its rows (the pattern's size fixes which way a row runs).
std::vector<int> CornerOrder(cv::Size inner, int which) {
  std::vector<int> order;
  for (int row = 0; row < inner.height; ++row) {
    for (int column = 0; column < inner.width; ++column) {
      const int r = which & 1 ? inner.height - 1 - row : row;
      const int c = which & 2 ? inner.width - 1 - column : column;
      order.push_back(r * inner.width + c);
    }
  }
  return order;
}

struct CornerSet {
  std::vector<Eigen::Vector3d> corners;
  double rms_px = 0;
};

// Every corner triangulated from the given sightings (already in one order); RMS reprojection.
CornerSet TriangulateCorners(const map::Map& map, const std::vector<const BoardSighting*>& sightings) {
  CornerSet set;
  double sum = 0;
  int count = 0;
  const std::size_t n = sightings.front()->corners.size();
  for (std::size_t k = 0; k < n; ++k) {
    std::vector<calib::Pose> poses;
    std::vector<Eigen::Vector3d> rays;
    for (const BoardSighting* s : sightings) {
      poses.push_back(map.keyframes[s->keyframe].pose);
      rays.push_back(Ray(map.camera, s->corners[k]));
    }
    set.corners.push_back(TriangulateRays(poses, rays));
    for (const BoardSighting* s : sightings) {
      const double e = ReprojectionPx(map.camera, map.keyframes[s->keyframe].pose, set.corners.back(), s->corners[k]);
      sum += e * e;
      ++count;
    }
  }
  set.rms_px = std::sqrt(sum / std::max(count, 1));
  return set;
}

double SightingRmsPx(const map::Map& map, const BoardSighting& s, const std::vector<Eigen::Vector3d>& corners) {
  double sum = 0;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const double e = ReprojectionPx(map.camera, map.keyframes[s.keyframe].pose, corners[k], s.corners[k]);
    sum += e * e;
  }
  return std::sqrt(sum / std::max<std::size_t>(corners.size(), 1));
}

// `sighting` in the order that agrees with the sightings already ordered: of the four orders,
// the one whose corners, triangulated with them, it reprojects best. A wrong order pairs each
// corner with another one, and the rays miss each other by up to the board's size, except
// between two views that mirror each other across the board's axis (a walk round the board has
// such pairs): there the mirrored order meets too. Against several views it does not.
BoardSighting InBestOrder(const map::Map& map, const std::vector<const BoardSighting*>& ordered,
                          const BoardSighting& sighting, cv::Size inner) {
  BoardSighting best = sighting;
  double best_rms = 1e300;
  for (int which = 0; which < 4; ++which) {
    BoardSighting candidate{sighting.keyframe, {}};
    for (int k : CornerOrder(inner, which)) candidate.corners.push_back(sighting.corners[k]);
    std::vector<const BoardSighting*> with = ordered;
    with.push_back(&candidate);
    const double rms = SightingRmsPx(map, candidate, TriangulateCorners(map, with).corners);
    if (rms < best_rms) {
      best_rms = rms;
      best = std::move(candidate);
    }
  }
  return best;
}

// Every sighting put in one order: each added in turn in the order that agrees with those before
// it, then each ordered again against all the others (an early choice between two mirrored views
// is then outvoted).
std::vector<BoardSighting> InOneOrder(const map::Map& map, const std::vector<BoardSighting>& sightings,
                                      std::size_t reference, cv::Size inner) {
  std::vector<BoardSighting> ordered{sightings[reference]};
  for (std::size_t i = 0; i < sightings.size(); ++i) {
    if (i == reference) continue;
    std::vector<const BoardSighting*> before;
    for (const BoardSighting& o : ordered) before.push_back(&o);
    ordered.push_back(InBestOrder(map, before, sightings[i], inner));
  }
  for (std::size_t i = 1; i < ordered.size(); ++i) {
    std::vector<const BoardSighting*> others;
    for (std::size_t j = 0; j < ordered.size(); ++j)
      if (j != i) others.push_back(&ordered[j]);
    ordered[i] = InBestOrder(map, others, ordered[i], inner);
  }
  return ordered;
}

// The widest angle between two rays (each in its keyframe's camera frame, `poses` the keyframes'),
// from the pixels alone: triangulating from views too close is what it guards against.
double WidestRayAngleDeg(const std::vector<calib::Pose>& poses, const std::vector<Eigen::Vector3d>& rays) {
  double widest = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d a = poses[i].q_cw.conjugate() * rays[i];
    for (std::size_t j = i + 1; j < rays.size(); ++j) {
      const Eigen::Vector3d b = poses[j].q_cw.conjugate() * rays[j];
      widest = std::max(widest, std::acos(std::clamp(a.dot(b), -1.0, 1.0)) / kDeg);
    }
  }
  return widest;
}

// The widest angle between two sightings' rays to the board's middle corner (the angle between
// the two views at the board).
double WidestAngleDeg(const map::Map& map, const std::vector<const BoardSighting*>& sightings) {
  std::vector<calib::Pose> poses;
  std::vector<Eigen::Vector3d> rays;
  for (const BoardSighting* s : sightings) {
    poses.push_back(map.keyframes[s->keyframe].pose);
    rays.push_back(Ray(map.camera, s->corners[s->corners.size() / 2]));
  }
  return WidestRayAngleDeg(poses, rays);
}

std::string Format(const char* format, double a, double b = 0, double c = 0, double d = 0) {
  char text[256];
  std::snprintf(text, sizeof text, format, a, b, c, d);
  return text;
}

// The estimate's checks of the floor it stands on (FitFromCameraHeight), set from the maps in
// docs/mapping.md, "The floor under the estimate": right floors had at most 0.2 % of the points
// below them and the cameras within a few % of one height over them; wrong ones 1.4 % and more.
constexpr double kMostPointsBelowFloor = 0.01;
constexpr double kMostCameraHeightSpread = 0.35;

}  // namespace

Sim3 Compose(const Sim3& a, const Sim3& b) {
  Sim3 c;
  c.scale = a.scale * b.scale;
  c.R = a.R * b.R;
  c.t = a.scale * (a.R * b.t) + a.t;
  return c;
}

namespace {

// The board's corners in one grey image, or none.
std::vector<Eigen::Vector2d> BoardCornersIn(const cv::Mat& gray, cv::Size inner) {
  std::vector<Eigen::Vector2d> corners;
  if (gray.empty()) return corners;
  for (const cv::Point2f& p : calib::FindChessboardCorners(gray, inner)) corners.emplace_back(p.x, p.y);
  return corners;
}

}  // namespace

std::vector<BoardSighting> FindBoard(const map::Map& map, const KeyframeImages& images, cv::Size inner,
                                     const std::function<void(int, int)>& progress, const CancellationToken& cancel) {
  // Keyframes in parallel (a detector that misses takes ~0.3 s on a 640x480 frame), in order.
  const int total = static_cast<int>(map.keyframes.size());
  std::vector<std::optional<BoardSighting>> found(map.keyframes.size());
  std::mutex progress_mutex;
  int done = 0;
  cv::parallel_for_(cv::Range(0, total), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      if (cancel.IsCancelled()) return;
      std::vector<Eigen::Vector2d> corners = BoardCornersIn(images(static_cast<std::size_t>(k)), inner);
      if (!corners.empty()) found[k] = BoardSighting{static_cast<std::size_t>(k), std::move(corners)};
      const std::lock_guard<std::mutex> lock(progress_mutex);
      ++done;
      if (progress) progress(done, total);
    }
  });
  cancel.ThrowIfCancelled("stopped looking for the board; the map was not changed");
  std::vector<BoardSighting> sightings;
  for (auto& s : found)
    if (s) sightings.push_back(std::move(*s));
  return sightings;
}

struct BoardSearchInBackground::State {
  enum class Image : char { kNotStarted, kStarted, kDone };
  std::vector<std::string> names;
  ReadImage read;
  cv::Size inner;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<Image> images;                        // under mutex
  std::vector<std::vector<Eigen::Vector2d>> corners;  // under mutex; an image's, once kDone
  std::exception_ptr failure;                       // under mutex: the first image that threw
  bool stopping = false;                            // under mutex
  std::vector<std::thread> threads;

  // Searches image i and records it (the first of two searches of one image to finish counts).
  void Search(std::size_t i) {
    std::vector<Eigen::Vector2d> found;
    std::exception_ptr thrown;
    try {
      found = BoardCornersIn(read(names[i]), inner);
    } catch (...) {
      thrown = std::current_exception();
    }
    const std::lock_guard lock(mutex);
    if (thrown && !failure) failure = thrown;
    if (images[i] != Image::kDone) {
      images[i] = Image::kDone;
      corners[i] = std::move(found);
    }
    changed.notify_all();
  }

  // The first image of `wanted` in `state` (under mutex), marked started; nullopt when none.
  std::optional<std::size_t> Take(const std::vector<std::size_t>& wanted, Image state) {
    for (std::size_t i : wanted) {
      if (images[i] != state) continue;
      images[i] = Image::kStarted;
      return i;
    }
    return std::nullopt;
  }
};

namespace {

void SearchInTheBackground(BoardSearchInBackground::State& state) {
  pthread_setname_np(pthread_self(), "arview-board");  // shown by top -H
  // Nice 19, the lowest priority, rather than SCHED_IDLE: a nice-19 thread still gets a little time on a
  // machine that other work keeps busy, so that the join in the destructor cannot wait forever.
  // Failing to lower it costs only the priority.
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  (void)setpriority(PRIO_PROCESS, tid, 19);
  std::vector<std::size_t> all(state.names.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  for (;;) {
    std::optional<std::size_t> image;
    {
      const std::lock_guard lock(state.mutex);
      if (state.stopping) return;
      image = state.Take(all, BoardSearchInBackground::State::Image::kNotStarted);
    }
    if (!image) return;
    state.Search(*image);
  }
}

}  // namespace

BoardSearchInBackground::BoardSearchInBackground(std::vector<std::string> names, ReadImage read,
                                                 cv::Size inner_corners, int threads)
    : state_(std::make_shared<State>()) {
  state_->names = std::move(names);
  state_->read = std::move(read);
  state_->inner = inner_corners;
  state_->images.assign(state_->names.size(), State::Image::kNotStarted);
  state_->corners.resize(state_->names.size());
  for (int t = 0; t < std::max(1, threads); ++t) state_->threads.emplace_back(SearchInTheBackground, std::ref(*state_));
}

BoardSearchInBackground::~BoardSearchInBackground() {
  {
    const std::lock_guard lock(state_->mutex);
    state_->stopping = true;
  }
  for (std::thread& t : state_->threads) t.join();
}

std::vector<BoardSighting> BoardSearchInBackground::Sightings(const map::Map& map,
                                                              const std::function<void(int, int)>& progress,
                                                              const CancellationToken& cancel) {
  State& s = *state_;
  std::unordered_map<std::string, std::size_t> by_name;
  for (std::size_t i = 0; i < s.names.size(); ++i) by_name.emplace(s.names[i], i);
  std::vector<std::size_t> wanted;  // the keyframes' images, in keyframe order
  std::vector<std::optional<BoardSighting>> found(map.keyframes.size());
  const int total = static_cast<int>(map.keyframes.size());
  int searched_here = 0;
  for (std::size_t k = 0; k < map.keyframes.size(); ++k) {
    const auto it = by_name.find(map.keyframes[k].name);
    if (it != by_name.end()) {
      wanted.push_back(it->second);
      continue;
    }
    cancel.ThrowIfCancelled("stopped looking for the board; the map was not changed");
    std::vector<Eigen::Vector2d> corners = BoardCornersIn(s.read(map.keyframes[k].name), s.inner);
    if (!corners.empty()) found[k] = BoardSighting{k, std::move(corners)};
    ++searched_here;
  }
  for (;;) {
    std::optional<std::size_t> image;
    std::size_t done = 0;
    {
      const std::lock_guard lock(s.mutex);
      if (s.failure) std::rethrow_exception(s.failure);
      done = static_cast<std::size_t>(
          std::count_if(wanted.begin(), wanted.end(), [&](std::size_t i) { return s.images[i] == State::Image::kDone; }));
      // Not all done: one is not started, or a background thread holds it.
      if (done < wanted.size()) image = s.Take(wanted, State::Image::kNotStarted);
      if (done < wanted.size() && !image) image = s.Take(wanted, State::Image::kStarted);
    }
    if (progress) progress(searched_here + static_cast<int>(done), total);
    if (!image) break;
    cancel.ThrowIfCancelled("stopped looking for the board; the map was not changed");
    s.Search(*image);
  }
  const std::lock_guard lock(s.mutex);
  s.stopping = true;  // the images no keyframe was made from are not needed
  for (std::size_t k = 0, w = 0; k < map.keyframes.size(); ++k) {
    if (!by_name.count(map.keyframes[k].name)) continue;
    const std::size_t i = wanted[w++];
    if (!s.corners[i].empty()) found[k] = BoardSighting{k, s.corners[i]};
  }
  std::vector<BoardSighting> sightings;
  for (auto& f : found)
    if (f) sightings.push_back(std::move(*f));
  return sightings;
}

TriangulatedBoard TriangulateBoard(const map::Map& map, const std::vector<BoardSighting>& sightings, cv::Size inner) {
  if (sightings.size() < 2) {
    throw map::MapError("the board was found whole in " + std::to_string(sightings.size()) + " of " +
                        std::to_string(map.keyframes.size()) +
                        " keyframes, at least 2 needed: film it whole, from two sides, or check --board (inner "
                        "corners, e.g. 9x6 for a board of 10 x 7 squares)");
  }
  // The reference: the sighting that sees the board largest (its corners the most exact).
  auto spread = [](const BoardSighting& s) { return (s.corners.front() - s.corners.back()).norm(); };
  const auto reference =
      std::max_element(sightings.begin(), sightings.end(), [&](const auto& a, const auto& b) { return spread(a) < spread(b); });
  const std::vector<BoardSighting> ordered =
      InOneOrder(map, sightings, static_cast<std::size_t>(reference - sightings.begin()), inner);

  std::vector<const BoardSighting*> kept;
  for (const BoardSighting& s : ordered) kept.push_back(&s);
  if (const double widest = WidestAngleDeg(map, kept); widest < kMinWidestAngleDeg) {
    throw map::MapError(Format("the board was seen from nearly one direction (its views %.1f degrees apart at most, "
                               "3 needed): film it from two sides",
                               widest));
  }
  CornerSet set = TriangulateCorners(map, kept);
  // Drop the sighting that agrees least until every one agrees (a corner found on the wrong
  // square, a keyframe posed wrongly): one at a time, as one bad sighting pulls every corner.
  while (kept.size() > 2) {
    std::size_t worst = 0;
    double worst_rms = 0;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const double rms = SightingRmsPx(map, *kept[i], set.corners);
      if (rms > worst_rms) {
        worst_rms = rms;
        worst = i;
      }
    }
    if (worst_rms <= kSightingAgreementPx) break;
    kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(worst));
    set = TriangulateCorners(map, kept);
  }
  TriangulatedBoard board;
  board.corners = set.corners;
  board.rms_reprojection_px = set.rms_px;
  board.sightings_dropped = static_cast<int>(ordered.size() - kept.size());
  for (const BoardSighting* s : kept) board.keyframes.push_back(s->keyframe);
  board.widest_angle_deg = WidestAngleDeg(map, kept);
  if (set.rms_px > kSightingAgreementPx) {
    throw map::MapError(Format("the board's sightings do not agree (corners %.1f px apart from their triangulation): "
                               "a wrong --board size, or a map whose keyframes are posed wrongly",
                               set.rms_px));
  }
  if (board.widest_angle_deg < kMinWidestAngleDeg) {
    throw map::MapError(Format("the board's sightings that agree see it from nearly one direction (%.1f degrees apart "
                               "at most, 3 needed): film it from two sides",
                               board.widest_angle_deg));
  }
  return board;
}

MetricFit FitFromBoard(const map::Map& map, const TriangulatedBoard& board, const BoardSpec& spec) {
  const cv::Size inner = spec.inner_corners;
  std::vector<Eigen::Vector3d> grid;  // the true corners, centred on the board's middle
  for (int row = 0; row < inner.height; ++row)
    for (int column = 0; column < inner.width; ++column)
      grid.emplace_back((column - (inner.width - 1) / 2.0) * spec.square, -(row - (inner.height - 1) / 2.0) * spec.square, 0);
  Sim3 to_board = EstimateSim3(board.corners, grid, true, "the board's corners");
  // The board's z (x along its rows, y against their order) may point into the floor: the
  // cameras, which look at its printed side, are on the side up is.
  double side = 0;
  for (std::size_t k : board.keyframes) side += to_board(map.keyframes[k].pose.Center()).z();
  if (side < 0) {
    const Eigen::Matrix3d half_turn = Eigen::Vector3d(1, -1, -1).asDiagonal();
    to_board.R = half_turn * to_board.R;
    to_board.t = half_turn * to_board.t;
  }
  double sum = 0;
  for (std::size_t k = 0; k < grid.size(); ++k) sum += (to_board(board.corners[k]) - grid[k]).squaredNorm();
  MetricFit fit;
  fit.fit_rms_m = std::sqrt(sum / grid.size());
  if (fit.fit_rms_m > 0.2 * spec.square) {
    throw map::MapError(Format("the board's triangulated corners do not form a %gx%g grid (%.1f%% of a square off "
                               "after the fit): is --board right?",
                               inner.width, inner.height, 100 * fit.fit_rms_m / spec.square));
  }
  fit.to_metric = spec.on_floor ? to_board : FloorFrame(map, FindFloor(map), to_board.scale);
  // The scale's error from the corners' scatter: a residual σ over N corners spread by r.
  double spread = 0;
  for (const auto& g : grid) spread += g.squaredNorm();
  spread = std::sqrt(spread / grid.size());
  fit.frame.scale_source = map::ScaleSource::kBoard;
  fit.frame.z_up = true;
  fit.frame.scale_error = fit.fit_rms_m / (spread * std::sqrt(static_cast<double>(grid.size())));
  char how[320];
  std::snprintf(how, sizeof how,
                "chessboard %dx%d of %.4g m squares seen whole in %zu keyframes (%d dropped), corners %.2f px, fit %.1f "
                "mm; %s",
                inner.width, inner.height, spec.square, board.keyframes.size(), board.sightings_dropped,
                board.rms_reprojection_px, 1000 * fit.fit_rms_m,
                spec.on_floor ? "up from its normal, origin at its centre" : "up and origin from the floor");
  fit.frame.how = how;
  return fit;
}

TriangulatedPoint TriangulatePoint(const map::Map& map, const std::vector<PointSighting>& sightings) {
  if (sightings.size() < 2) throw map::MapError("a point needs its pixel in at least two keyframes");
  std::vector<calib::Pose> poses;
  std::vector<Eigen::Vector3d> rays;
  std::vector<Eigen::Vector2d> pixels;
  std::set<const map::Keyframe*> used;
  for (const PointSighting& s : sightings) {
    const auto k = std::find_if(map.keyframes.begin(), map.keyframes.end(), [&](const map::Keyframe& kf) {
      return kf.name == s.keyframe_name || std::filesystem::path(kf.name).filename() == s.keyframe_name;
    });
    if (k == map.keyframes.end()) throw map::MapError("no keyframe named '" + s.keyframe_name + "' in the map (keyframes.txt lists them)");
    // One keyframe twice gives one ray twice: the rays meet anywhere along it.
    if (!used.insert(&*k).second) {
      throw map::MapError("keyframe '" + k->name + "' is given twice for one point: its pixel is needed in two "
                          "different keyframes, whose rays cross at the point");
    }
    poses.push_back(k->pose);
    rays.push_back(Ray(map.camera, s.pixel));
    pixels.push_back(s.pixel);
  }
  if (const double widest = WidestRayAngleDeg(poses, rays); widest < kMinWidestAngleDeg) {
    throw map::MapError(Format("the keyframes given for a point see it from nearly one direction (their rays %.1f "
                               "degrees apart at most, 3 needed): give its pixel in keyframes further apart",
                               widest));
  }
  TriangulatedPoint point;
  point.xyz = TriangulateRays(poses, rays);
  double widest = 0, depth = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double e = ReprojectionPx(map.camera, poses[i], point.xyz, pixels[i]);
    if (e > 4) {
      throw map::MapError(Format("the pixels given for a point do not meet in the map (%.1f px off in one keyframe): "
                                 "are they the same scene point?",
                                 e));
    }
    depth = std::max(depth, poses[i].ToCamera(point.xyz).z());
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      const Eigen::Vector3d a = (poses[i].Center() - point.xyz).normalized(), b = (poses[j].Center() - point.xyz).normalized();
      widest = std::max(widest, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
    }
  }
  // A pixel's error moves the point sideways by depth / f, and along the rays by that over the
  // sine of the angle between them.
  point.uncertainty = depth / map.camera.fx / std::max(std::sin(widest), 1e-3);
  return point;
}

MetricFit FitFromDistance(const map::Map& map, const TriangulatedPoint& a, const TriangulatedPoint& b, double metres) {
  const double units = (a.xyz - b.xyz).norm();
  if (!(metres > 0) || units < 1e-12) throw map::MapError("the two points of a known distance must differ");
  MetricFit fit;
  fit.to_metric = FloorFrame(map, FindFloor(map), metres / units);
  fit.frame.scale_source = map::ScaleSource::kKnownDistance;
  fit.frame.z_up = true;
  fit.frame.scale_error = std::hypot(a.uncertainty, b.uncertainty) / units;
  fit.frame.how = Format("%.4g m between two points the user gave (%.4g map units apart); up and origin from the floor",
                         metres, units);
  return fit;
}

MetricFit FitFromCameraHeight(const map::Map& map) {
  double below = 0;
  const Plane floor = FindFloor(map, &below);
  const double height = MedianHeightOverFloor(map, floor);
  if (!(height > 0)) throw map::MapError("the cameras are not above the floor found in the map's points");
  // A floor has the scene above it: points below it beyond the noise say the plane is something
  // else (a wall's edge, a table, a reflection), and the scale from it could be off by any factor.
  if (below > kMostPointsBelowFloor) {
    throw map::MapError(Format("the floor found is not to be trusted: %.1f%% of the map's points lie below it (a "
                               "floor has under %.0f%%); give the scale with 'arview map scale --board' or --distance",
                               100 * below, 100 * kMostPointsBelowFloor));
  }
  std::vector<double> relative_heights;  // over the floor, as fractions of the median
  for (const Eigen::Vector3d& c : Centres(map)) relative_heights.push_back(floor.Distance(c) / height);
  const double low = Percentile(relative_heights, 0.1), high = Percentile(relative_heights, 0.9);
  // The cameras' heights over the floor vary by half their 10-90 % range: a floor tilted against
  // the walk, or a camera raised and lowered, takes the median that far from any one height. The
  // typical height's error holds only where they vary less; far more and the floor is likely wrong.
  const double spread = (high - low) / 2;
  if (spread > kMostCameraHeightSpread) {
    throw map::MapError(Format("the floor found is not to be trusted: the cameras' heights over it vary by +-%.0f%% "
                               "(10-90 %%; more than %.0f%%); give the scale with 'arview map scale --board' or "
                               "--distance",
                               100 * spread, 100 * kMostCameraHeightSpread));
  }
  MetricFit fit;
  fit.to_metric = FloorFrame(map, floor, kTypicalCameraHeight / height);
  fit.frame.scale_source = map::ScaleSource::kCameraHeight;
  fit.frame.z_up = true;
  fit.frame.scale_error = std::max(kCameraHeightRelativeError, spread);
  fit.frame.how = Format("an estimate: the cameras taken to be %.2f m above the floor (likely error +-%.0f%%), ",
                         kTypicalCameraHeight, 100 * fit.frame.scale_error) +
                  Format("%.2f-%.2f m over it (10-90 %%), %.1f%% of the points below it; ", low * kTypicalCameraHeight,
                         high * kTypicalCameraHeight, 100 * below) +
                  (spread > kCameraHeightRelativeError ? "doubtful: the cameras' heights over the floor vary; " : "") +
                  "up and origin from the floor";
  return fit;
}

void ApplyMetricFit(const MetricFit& fit, map::Map* map) {
  for (map::Keyframe& k : map->keyframes) k.pose = calib::Pose::FromRigid(fit.to_metric.TransformPose(k.pose.ToRigid()));
  for (map::MapPoint& p : map->points) p.xyz = fit.to_metric(p.xyz);
  const Sim3 from_colmap = Compose(fit.to_metric, map->frame.from_colmap);
  map->frame = fit.frame;
  map->frame.from_colmap = from_colmap;
}

}  // namespace arview::mapping
