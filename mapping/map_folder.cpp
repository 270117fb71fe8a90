// A built map's folder: the map made metric with its COLMAP model (MakeMetric for `arview map`,
// ScaleMapFolder for `arview map scale`; the model's frame record, arview_frame.txt), the
// folder's files written (WriteMapFiles: check.json, keyframes.txt, map.png, map.arvmap last)
// and its self-check computed again (RecheckMap). Apart from the build's sequence (MapBuild,
// mapping/colmap_pipeline.cpp); declared in mapping/colmap_pipeline.h, mapping/colmap_stages.h
// and mapping/map_build_stages.h.

#include "mapping/map_build_stages.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "base/atomic_file.h"
#include "base/image_file.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/map_extend.h"
#include "mapping/self_calibration.h"
#include "recordings/trajectory.h"

namespace arview::mapping {

namespace fs = std::filesystem;

namespace {

// A COLMAP model that arview moved into a metric frame says so in <model>/arview_frame.txt: the
// request it was made from and the frame record. A re-run of `arview map` whose COLMAP stages
// are all skipped reads that model again: with the same request it is taken as it is (the map
// file comes out byte-identical), with another one the new fit starts from it.
constexpr const char* kModelFrameFile = "arview_frame.txt";

std::string RequestSignature(const ScaleRequest& r) {
  switch (r.from) {
    case ScaleFrom::kNone: return "none";
    case ScaleFrom::kCameraHeight: return "camera-height";
    case ScaleFrom::kKnownDistance: return "known-distance";
    case ScaleFrom::kBoard: {
      char text[96];
      std::snprintf(text, sizeof text, "board %dx%d %.17g %s", r.board.inner_corners.width, r.board.inner_corners.height,
                    r.board.square, r.board.on_floor ? "floor" : "off-floor");
      return text;
    }
  }
  return "none";
}

void WriteModelFrame(const fs::path& model_dir, const std::string& signature, const map::MapFrame& f) {
  std::ostringstream text;
  text.precision(17);
  text << "arview map frame 1\nrequest " << signature << "\nsource " << static_cast<int>(f.scale_source) << " "
       << (f.z_up ? 1 : 0) << " " << f.scale_error << "\nfrom_colmap " << f.from_colmap.scale;
  for (int i = 0; i < 9; ++i) text << " " << f.from_colmap.R(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) text << " " << f.from_colmap.t[i];
  text << "\nhow " << f.how << "\n";
  WriteFileAtomically(model_dir / kModelFrameFile, text.str());
}

struct ModelFrame {
  std::string signature;
  map::MapFrame frame;
};

// Nothing when the model has no record (COLMAP's own frame) or an unreadable one.
std::optional<ModelFrame> ReadModelFrame(const fs::path& model_dir) {
  std::ifstream in(model_dir / kModelFrameFile);
  std::string line;
  if (!in || !std::getline(in, line) || line != "arview map frame 1") return std::nullopt;
  ModelFrame m;
  int source = 0, z_up = 0;
  std::string key;
  if (!std::getline(in, line) || line.rfind("request ", 0) != 0) return std::nullopt;
  m.signature = line.substr(8);
  if (!(in >> key >> source >> z_up >> m.frame.scale_error) || key != "source" || source < 0 || source > 3)
    return std::nullopt;
  m.frame.scale_source = static_cast<map::ScaleSource>(source);
  m.frame.z_up = z_up == 1;
  if (!(in >> key >> m.frame.from_colmap.scale) || key != "from_colmap") return std::nullopt;
  for (int i = 0; i < 9; ++i) in >> m.frame.from_colmap.R(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) in >> m.frame.from_colmap.t[i];
  in >> std::ws;
  if (!in || !std::getline(in, line) || line.rfind("how ", 0) != 0) return std::nullopt;
  m.frame.how = line.substr(4);
  return m;
}

// The COLMAP model in <model_dir> moved into the metric frame: written beside it
// (colmap_model.h's WriteTransformedModel, with its frame record), then put in its place, so that
// a failed write leaves the model as it was.
void TransformColmapModel(const fs::path& model_dir, const Sim3& transform, const std::string& signature,
                          const map::MapFrame& frame) {
  const fs::path staged = model_dir.string() + ".metric", old = model_dir.string() + ".old";
  std::error_code ec;
  fs::remove_all(staged, ec);
  fs::remove_all(old, ec);
  try {
    WriteTransformedModel(model_dir, staged, transform);
    WriteModelFrame(staged, signature, frame);
  } catch (...) {
    fs::remove_all(staged, ec);
    throw;
  }
  fs::rename(model_dir, old);
  fs::rename(staged, model_dir);
  fs::remove_all(old, ec);
}

// check.json's two distances follow the map into metres.
void ScaleCheckDistances(double scale, MapCheck* check) {
  check->path_extent *= scale;
  check->scene_depth *= scale;
}

}  // namespace

cv::Mat GreyImageOrNone(const fs::path& file) {
  try {
    return ReadImageFile(file, cv::IMREAD_GRAYSCALE);
  } catch (const Error&) {
    return cv::Mat();
  }
}

KeyframeImages KeyframeImagesIn(const map::Map& map, const std::vector<fs::path>& roots) {
  return [&map, roots](std::size_t k) {
    for (const fs::path& root : roots) {
      const fs::path file = root / map.keyframes[k].name;
      std::error_code ec;
      if (fs::is_regular_file(file, ec)) return GreyImageOrNone(file);
    }
    return cv::Mat();
  };
}

namespace {

// The requested fit. Throws MapError when it cannot be made.
// `board_search`: the board's search already under way, or null to search the keyframes now.
MetricFit FitRequested(const map::Map& map, const ScaleRequest& request, const KeyframeImages& images,
                       const MapBuildOptions& options, const MapBuildCallbacks& cb,
                       BoardSearchInBackground* board_search = nullptr) {
  switch (request.from) {
    case ScaleFrom::kBoard: {
      const auto progress = [&](int done, int total) {
        if (cb.progress) cb.progress("board", done, total);
      };
      const std::vector<BoardSighting> seen =
          board_search ? board_search->Sightings(map, progress, options.cancel)
                       : FindBoard(map, images, request.board.inner_corners, progress, options.cancel);
      return FitFromBoard(map, TriangulateBoard(map, seen, request.board.inner_corners), request.board);
    }
    case ScaleFrom::kKnownDistance: {
      // One end, then the other: an error is about the first end given wrongly.
      const TriangulatedPoint a = TriangulatePoint(map, request.point_a);
      const TriangulatedPoint b = TriangulatePoint(map, request.point_b);
      return FitFromDistance(map, a, b, request.distance_m);
    }
    case ScaleFrom::kCameraHeight:
      return FitFromCameraHeight(map);
    case ScaleFrom::kNone:
      break;
  }
  throw map::MapError("no scale source requested");
}

}  // namespace

void MakeMetric(const KeyframeImages& images, BoardSearchInBackground* board_search, const MapBuildOptions& options,
                const MapBuildCallbacks& cb, const std::function<map::Map()>& read_model, MapBuildResult* result) {
  // The model read may be one an earlier run moved already: its frame comes with it.
  const std::optional<ModelFrame> earlier = ReadModelFrame(result->model_dir);
  if (earlier) {
    result->map.frame = earlier->frame;
    ScaleRequest asked = options.scale;
    if (earlier->signature == RequestSignature(asked) && asked.from == ScaleFrom::kBoard &&
        earlier->frame.scale_source != map::ScaleSource::kBoard) {
      result->scale_failure = "the board could not be used when this model was made (the output of that run of "
                              "arview map says why)";
    }
    if (earlier->signature == RequestSignature(asked) || asked.from == ScaleFrom::kNone) return;
  }
  if (options.scale.from == ScaleFrom::kNone) return;
  std::optional<MetricFit> fit;
  try {
    fit = FitRequested(result->map, options.scale, images, options, cb, board_search);
  } catch (const map::MapError& e) {
    if (options.scale.from == ScaleFrom::kCameraHeight) {
      if (cb.note) cb.note(std::string("the map stays in COLMAP's units and orientation: ") + e.what());
      return;
    }
    result->scale_failure = e.what();
    ScaleRequest estimate;
    estimate.from = ScaleFrom::kCameraHeight;
    try {
      fit = FitRequested(result->map, estimate, images, options, cb);
    } catch (const map::MapError&) {
      return;
    }
  }
  options.cancel.ThrowIfCancelled("COLMAP's stages are finished and kept; the map file was not written");
  ApplyMetricFit(*fit, &result->map);
  // What is asked is recorded, also when a board fell back to the estimate: the same command
  // again then takes the model as it is rather than failing on the board a second time.
  TransformColmapModel(result->model_dir, fit->to_metric, RequestSignature(options.scale), result->map.frame);
  const map::MapFrame frame = result->map.frame;
  result->map = read_model();
  result->map.frame = frame;
  ScaleCheckDistances(fit->to_metric.scale, &result->check);
}

// check.json, the keyframes, the top view, and the map file last: a disk that fills at an
// earlier file fails the command without a new map.arvmap beside the error (each file is
// written atomically; a previous map stays whole).
void WriteMapFiles(const MapBuildResult& result, const fs::path& out_dir, const MapBuildOptions& options,
                   const MapBuildCallbacks& cb) {
  WriteMapCheck(result.check, out_dir / kMapCheckFileName);
  if (cb.warning)
    for (const std::string& w : result.check.warnings) cb.warning(w);
  RequireModelValuesInRange(result.map, result.model_dir);
  options.cancel.ThrowIfCancelled("COLMAP's stages are finished and kept; the map file was not written");
  WriteKeyframesTum(result.map, out_dir / "keyframes.txt");
  WriteTopView(result.map, out_dir / "map.png");
  map::SaveMap(result.map, out_dir / map::kMapFileName);
}

MapCheck RecheckMap(const fs::path& map_dir) {
  const map::Map built = map::LoadMap(map_dir);
  const fs::path database = map_dir / "database.db";
  int models = 0;
  const fs::path model_dir = LargestModel(map_dir / "sparse", &models, {});
  if (model_dir.empty())
    throw map::MapError((map_dir / "sparse").string() + ": no COLMAP model to check (the folder arview map wrote keeps it)");
  FrameLookup frames;
  for (const map::Keyframe& k : built.keyframes) frames[k.name] = {k.frame_index, k.timestamp};
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  const map::Map model = ReadColmapMap(model_dir, database, frames, {}, &keypoints, false);
  MapCheck check = CheckMap(model, keypoints, ReadTwoViewGeometries(database, model));
  // A map made without a calibration keeps the warning on its refined intrinsics.
  std::error_code ec;
  if (fs::exists(map_dir / "camera.yaml", ec) && !calib::LoadCamera(map_dir / "camera.yaml").calibrated) {
    for (const std::string& problem : ImplausibleIntrinsics(built.camera)) check.warnings.push_back("is self-calibrated implausibly: " + problem);
  }
  WriteMapCheck(check, map_dir / kMapCheckFileName);
  return check;
}

map::Map ScaleMapFolder(const fs::path& map_dir, const recordings::Recording* recording, const ScaleRequest& request,
                        const MapBuildOptions& options, const MapBuildCallbacks& cb) {
  MapBuildResult result;
  result.map = map::LoadMap(map_dir);
  int models = 0;
  result.model_dir = LargestModel(map_dir / "sparse", &models, {});
  if (result.model_dir.empty())
    throw map::MapError((map_dir / "sparse").string() + ": no COLMAP model (the folder arview map wrote keeps it)");
  // The model moves with the map: it must be the map's own (another map's would be rescaled), and
  // a map file moved after COLMAP takes its model along through that move.
  const std::optional<Sim3> to_map_file = RequireOwnModel(result.model_dir, result.map, map_dir);
  const std::optional<MapCheck> check = ReadMapCheck(map_dir / kMapCheckFileName);
  if (check) result.check = *check;
  std::vector<fs::path> roots{map_dir / "images", map_dir};
  if (recording) roots.push_back(recording->root);
  const MetricFit fit = FitRequested(result.map, request, KeyframeImagesIn(result.map, roots), options, cb);
  options.cancel.ThrowIfCancelled("the map was not changed");
  ApplyMetricFit(fit, &result.map);
  TransformColmapModel(result.model_dir, to_map_file ? Compose(fit.to_metric, *to_map_file) : fit.to_metric,
                       RequestSignature(request), result.map.frame);
  ScaleCheckDistances(fit.to_metric.scale, &result.check);
  WriteMapFiles(result, map_dir, options, cb);
  if (!check) RecheckMap(map_dir);  // a map from before the check: computed now, in metres
  return std::move(result.map);
}

void WriteKeyframesTum(const map::Map& map, const fs::path& file) {
  recordings::Trajectory trajectory;
  for (const map::Keyframe& k : map.keyframes) trajectory.push_back({k.timestamp, k.pose});
  try {
    recordings::WriteTum(trajectory, file, "arview map: the frames COLMAP registered (the keyframes of the map)");
  } catch (const std::exception& e) {
    throw map::MapError(file.string() + ": cannot write keyframes (" + e.what() + ")");
  }
}

}  // namespace arview::mapping
