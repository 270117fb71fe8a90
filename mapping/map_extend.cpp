#include "mapping/map_extend.h"


#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "base/atomic_file.h"
#include "base/cancellation.h"
#include "base/input_guard.h"
#include "base/process.h"
#include "map/descriptor_index.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/colmap_stages.h"
#include "mapping/frames_in_map.h"
#include "mapping/pair_matching.h"

namespace arview::mapping {

namespace fs = std::filesystem;
using json = nlohmann::json;

map::Map CarryFrameRecord(const map::Map& old_map, map::Map model) {
  // Start from the old map whole, so that every record it carries besides the model (the frame
  // record: what the map's frame is, its scale and up) comes along without being named here.
  map::Map extended = old_map;
  extended.camera = model.camera;
  extended.keyframes = std::move(model.keyframes);
  extended.points = std::move(model.points);
  extended.descriptors = model.descriptors;
  extended.descriptor_point = std::move(model.descriptor_point);
  extended.descriptor_keyframe = std::move(model.descriptor_keyframe);
  // A venue's rooms: each keyframe it had keeps its room; the session's frames are in none.
  std::map<std::string, int> rooms;
  for (const map::Keyframe& k : old_map.keyframes) rooms[k.name] = k.room;
  for (map::Keyframe& k : extended.keyframes) {
    const auto it = rooms.find(k.name);
    k.room = it == rooms.end() ? -1 : it->second;
  }
  return extended;
}

Sim3 FitScaleAndShift(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  if (from.size() != to.size() || from.empty()) throw map::MapError("scale and shift: the two point lists differ");
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i];
    mean_to += to[i];
  }
  mean_from /= static_cast<double>(from.size());
  mean_to /= static_cast<double>(to.size());
  double cross = 0, spread = 0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    cross += (from[i] - mean_from).dot(to[i] - mean_to);
    spread += (from[i] - mean_from).squaredNorm();
  }
  Sim3 fit;
  fit.scale = spread > 0 ? cross / spread : 1.0;  // one keyframe: a shift alone
  fit.t = mean_to - fit.scale * mean_from;
  return fit;
}

namespace {

// The map folder as `arview map` left it.
struct OldMap {
  map::Map map;
  fs::path model_dir;
  fs::path database;
};

OldMap RequireExtendableMap(const fs::path& map_dir) {
  std::error_code ec;
  if (!fs::is_directory(map_dir, ec))
    throw map::MapError(map_dir.string() + ": no such map folder (arview map <recording> --out <map-dir> makes one)");
  OldMap old;
  old.map = map::LoadMap(map_dir);  // names map.arvmap when it is missing or damaged
  if (old.map.keyframes.empty()) throw map::MapError((map_dir / map::kMapFileName).string() + ": the map has no keyframes");
  old.database = map_dir / "database.db";
  const char* why_needed = "a map is extended in COLMAP's database, which the folder arview map wrote keeps";
  if (!fs::exists(old.database, ec)) throw map::MapError(old.database.string() + ": missing: " + why_needed);
  try {
    RequireRegularFile(old.database);
  } catch (const InputError& e) {
    throw map::MapError(std::string(e.what()) + " (" + why_needed + ")");
  }
  old.model_dir = LargestColmapModel(map_dir / "sparse");
  if (old.model_dir.empty())
    throw map::MapError((map_dir / "sparse").string() +
                        ": no COLMAP model to extend (the folder arview map wrote keeps it in sparse/<n>/)");
  // Before any COLMAP stage: COLMAP reads the model only when the mapper starts, and a damaged
  // file ends it in its own stack trace.
  RequireReadableModel(old.model_dir);
  return old;
}

bool SameCalibration(const calib::Camera& a, const calib::Camera& b) {
  const auto close = [](double x, double y) { return std::abs(x - y) <= 1e-6 * std::max(1.0, std::abs(x)); };
  for (int i = 0; i < 5; ++i)
    if (!close(a.dist[i], b.dist[i])) return false;
  return close(a.fx, b.fx) && close(a.fy, b.fy) && close(a.cx, b.cx) && close(a.cy, b.cy);
}

void RequireSameCamera(const calib::Camera& map_camera, const recordings::Recording& recording,
                       const MapBuildCallbacks& cb) {
  const calib::Camera& c = recording.camera;
  if (c.width != map_camera.width || c.height != map_camera.height) {
    throw map::MapError((recording.root / "camera.yaml").string() + ": the recording's frames are " +
                        std::to_string(c.width) + "x" + std::to_string(c.height) + ", the map's camera " +
                        std::to_string(map_camera.width) + "x" + std::to_string(map_camera.height) +
                        ": a map is extended with frames of its own camera");
  }
  if (!SameCalibration(c, map_camera) && cb.note)
    cb.note("the recording's calibration differs from the map's: the new frames are registered with the map's camera");
}

// Whatever the database's write-ahead log holds moved into the file itself and the log emptied,
// so that the file alone is the database (renamed over another, or replaced).
void CheckpointDatabase(const fs::path& database) {
  ColmapDatabase(database, ColmapDatabase::Access::kReadWrite)
      .Execute("PRAGMA wal_checkpoint(TRUNCATE);", "move its write-ahead log into the file");
}

// "session-2" for the first extension: the original session is the first. A name neither the
// images folder nor the database holds, so that the new frames' names are new to COLMAP.
std::string NextSessionName(const fs::path& map_dir, const std::vector<ColmapDatabase::ImageRow>& names) {
  for (int k = 2;; ++k) {
    const std::string session = "session-" + std::to_string(k);
    std::error_code ec;
    const bool used = fs::exists(map_dir / "images" / session, ec) ||
                      std::any_of(names.begin(), names.end(),
                                  [&](const auto& n) { return n.name.rfind(session + "/", 0) == 0; });
    if (!used) return session;
  }
}

// The SIFT settings the map was built with (its extraction's command line in
// stages/extract.inputs, or the last extension's record), so that the new frames' features are
// the old ones' kind. Nothing recorded: the options' own.
void TakeMapsSiftSettings(const fs::path& map_dir, MapBuildOptions* options) {
  std::ifstream in(map_dir / "stages" / "extract.inputs");
  std::string line, previous;
  bool found = false;
  while (std::getline(in, line)) {
    if (previous == "--SiftExtraction.max_num_features") {
      options->max_num_features = std::atoi(line.c_str());
      found = true;
    }
    if (previous == "--SiftExtraction.max_num_orientations") options->max_num_orientations = std::atoi(line.c_str());
    previous = line;
  }
  if (found) return;
  try {
    const json record = json::parse(std::ifstream(map_dir / kExtendRecordName));
    options->max_num_features = record.at("sift").at("max_num_features").get<int>();
    options->max_num_orientations = record.at("sift").at("max_num_orientations").get<int>();
  } catch (const std::exception&) {
    // No record: the options' settings.
  }
  options->max_num_features = std::max(options->max_num_features, 64);
  options->max_num_orientations = std::max(options->max_num_orientations, 1);
}

// The folder the extension works in; removed unless the extension was committed.
class PartialFolder {
 public:
  explicit PartialFolder(fs::path dir) : dir_(std::move(dir)) {
    std::error_code ec;
    fs::remove_all(dir_, ec);  // a run killed before (kill -9) left it: nothing in it is kept
    fs::create_directories(dir_, ec);
    if (ec) throw map::MapError(dir_.string() + ": cannot create the extension's work folder (" + ec.message() + ")");
  }
  ~PartialFolder() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  PartialFolder(const PartialFolder&) = delete;
  PartialFolder& operator=(const PartialFolder&) = delete;
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
};

// The new session's frames copied under <partial>/images/<session>/, their names prefixed with
// it (COLMAP's names must be new to the database; the images then sit where the tracker's
// keyframe-image readers look: <map-dir>/images/<name>).
ImageSet CopyIntoSession(const ImageSet& selected, const fs::path& images_root, const std::string& session,
                         const CancellationToken& cancel) {
  ImageSet set;
  set.root = images_root;
  for (const std::string& name : selected.names) {
    cancel.ThrowIfCancelled("stopped copying the new frames");
    const std::string prefixed = session + "/" + name;
    const fs::path target = images_root / prefixed;
    fs::create_directories(target.parent_path());
    std::error_code ec;
    fs::copy_file(selected.root / name, target, fs::copy_options::overwrite_existing, ec);
    if (ec) throw map::MapError(target.string() + ": cannot copy the frame there (" + ec.message() + ")");
    set.names.push_back(prefixed);
    set.lookup[prefixed] = selected.lookup.at(name);
  }
  return set;
}

// For each new frame, the old keyframes (indices into old.keyframes) that own the nearest
// neighbours of most of its descriptors (ratio 0.8), at most `wanted`, most votes first. A map
// without the row → keyframe table gives every keyframe.
std::vector<std::vector<int>> OldKeyframesNearest(const map::Map& old, const std::vector<cv::Mat>& new_descriptors,
                                                  int wanted, const CancellationToken& cancel) {
  const int keyframes = static_cast<int>(old.keyframes.size());
  std::vector<int> all(static_cast<std::size_t>(keyframes));
  for (int k = 0; k < keyframes; ++k) all[static_cast<std::size_t>(k)] = k;
  if (old.descriptors.empty() || old.descriptor_keyframe.size() != static_cast<std::size_t>(old.descriptors.rows) ||
      wanted >= keyframes)
    return std::vector<std::vector<int>>(new_descriptors.size(), all);
  const map::DescriptorIndex index(old.descriptors);
  std::vector<std::vector<int>> nearest;
  for (const cv::Mat& descriptors : new_descriptors) {
    cancel.ThrowIfCancelled("stopped choosing the keyframes to match");
    const std::vector<int> votes =
        map::NearestNeighbourVotes(index, old.descriptor_keyframe, static_cast<std::size_t>(keyframes), descriptors, 0.8f);
    std::vector<int> order = all;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return votes[static_cast<std::size_t>(a)] > votes[static_cast<std::size_t>(b)]; });
    order.resize(static_cast<std::size_t>(wanted));
    nearest.push_back(order);
  }
  return nearest;
}

// The pairs COLMAP matches: the new frames among themselves as `arview map` pairs them
// (--matcher), and each new frame with its nearest old keyframes.
std::vector<std::pair<std::string, std::string>> PairsToMatch(const OldMap& old, const ImageSet& session,
                                                              const fs::path& database, const MapExtendOptions& options) {
  const int n = static_cast<int>(session.names.size());
  const MapBuildOptions& build = options.build;
  const std::vector<ImagePair> among = ExhaustiveMatchingWanted(build, n)
                                           ? ExhaustivePairs(n)
                                           : SequentialPairs(n, build.sequential_overlap, build.quadratic_overlap);
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const ImagePair& p : among)
    pairs.emplace_back(session.names[static_cast<std::size_t>(p.first)], session.names[static_cast<std::size_t>(p.second)]);
  const std::vector<cv::Mat> descriptors = ReadImageDescriptors(database, session.names, build.cancel);
  const auto nearest = OldKeyframesNearest(old.map, descriptors, options.old_neighbours, build.cancel);
  for (std::size_t i = 0; i < session.names.size(); ++i)
    for (int k : nearest[i]) pairs.emplace_back(session.names[i], old.map.keyframes[static_cast<std::size_t>(k)].name);
  return pairs;
}

// COLMAP matches the pairs (matches_importer, its own matcher and verification) in steps of a
// sixteenth, so that the stage shows progress and a time left (one run prints nothing until done).
void MatchPairs(const std::vector<std::pair<std::string, std::string>>& pairs, const fs::path& database,
                const fs::path& work, const MapExtendOptions& options, const MapBuildCallbacks& cb) {
  for (const auto& [a, b] : pairs)
    for (const std::string* name : {&a, &b})
      if (name->empty() || name->find_first_of(" \t\r\n") != std::string::npos)
        throw map::MapError("'" + *name + "': a frame's name holds a space, which COLMAP's pair lists cannot hold");
  const std::size_t step = std::max<std::size_t>(8, (pairs.size() + 15) / 16);
  const int total = static_cast<int>(pairs.size());
  if (cb.progress) cb.progress("match", 0, total);
  for (std::size_t first = 0; first < pairs.size(); first += step) {
    const std::size_t last = std::min(pairs.size(), first + step);
    std::string list;
    for (std::size_t i = first; i < last; ++i) list += pairs[i].first + " " + pairs[i].second + "\n";
    const fs::path list_file = work / "pairs.txt";
    WriteFileAtomically(list_file, list);
    RunColmap(options.build, work, "match",
              {"matches_importer", "--database_path", database.string(), "--match_list_path", list_file.string(),
               "--match_type", "pairs", "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
               std::to_string(options.build.threads)},
              0, cb);
    if (cb.progress) cb.progress("match", static_cast<int>(last), total);
  }
}

// COLMAP's mapper continuing the old model with the old keyframes' poses constant: only the old
// keyframes and the new frames take part (old frames COLMAP never registered stay out).
void ContinueModel(const OldMap& old, const ImageSet& session, const fs::path& database, const fs::path& work,
                   const fs::path& continued, const MapExtendOptions& options, const MapBuildCallbacks& cb) {
  std::string list;
  for (const map::Keyframe& k : old.map.keyframes) list += k.name + "\n";
  for (const std::string& name : session.names) list += name + "\n";
  const fs::path list_file = work / "mapper_images.txt";
  WriteFileAtomically(list_file, list);
  fs::create_directories(continued);
  std::vector<std::string> args = ColmapMapperArgs(options.build, database, session.root, continued);
  args.insert(args.end(), {"--input_path", old.model_dir.string(), "--image_list_path", list_file.string(),
                           "--Mapper.fix_existing_images", "1", "--Mapper.multiple_models", "0"});
  RunColmap(options.build, work, "register", args,
            static_cast<int>(old.map.keyframes.size() + session.names.size()), cb);
}

// Pointers into `keyframes`, which must outlive the result (a temporary is refused below).
std::map<std::uint32_t, const map::Keyframe*> ById(const std::vector<map::Keyframe>& keyframes) {
  std::map<std::uint32_t, const map::Keyframe*> by_id;
  for (const map::Keyframe& k : keyframes) by_id[k.colmap_image_id] = &k;
  return by_id;
}
std::map<std::uint32_t, const map::Keyframe*> ById(std::vector<map::Keyframe>&&) = delete;

// COLMAP 3.8's mapper normalises its model after each global bundle adjustment (centred, scaled
// to a fixed extent; rotations untouched). The old keyframes' poses were held, so their centres
// moved by exactly that shift and scale: fitted on them and undone (colmap_model.h's
// WriteTransformedModel), the model is back in the map's own frame.
void RestoreMapFrame(const fs::path& old_model, const fs::path& continued, const fs::path& restored,
                     MapExtendResult* result) {
  const std::vector<map::Keyframe> before = ReadColmapCameraPath(old_model);
  // Kept in a variable: ById's pointers into a temporary dangled (found by AddressSanitizer).
  const std::vector<map::Keyframe> continued_path = ReadColmapCameraPath(continued);
  const auto after = ById(continued_path);
  std::vector<Eigen::Vector3d> from, to;
  for (const map::Keyframe& k : before) {
    if (const auto it = after.find(k.colmap_image_id); it != after.end()) {
      from.push_back(it->second->pose.Center());
      to.push_back(k.pose.Center());
    }
  }
  if (from.empty()) throw map::MapError(continued.string() + ": COLMAP's mapper kept none of the old keyframes");
  const Sim3 back = FitScaleAndShift(from, to);
  result->colmap_shift_scale = 1.0 / back.scale;
  // Written by arview (colmap_model.h): COLMAP's model_transformer ignores write errors and would
  // leave a truncated model on a full disk.
  WriteTransformedModel(continued, restored, back);
}

double RotationAngleDeg(const calib::Pose& a, const calib::Pose& b) {
  return Eigen::AngleAxisd(a.q_cw.conjugate() * b.q_cw).angle() * 180.0 / M_PI;
}

// How far each old keyframe moved (centre and rotation) between the old model and the extended
// map, and how large the old path is.
void MeasureDrift(const std::vector<map::Keyframe>& before, const map::Map& extended, MapExtendResult* result) {
  const auto after = ById(extended.keyframes);
  for (const map::Keyframe& a : before) {
    for (const map::Keyframe& b : before)
      result->path_extent = std::max(result->path_extent, (a.pose.Center() - b.pose.Center()).norm());
    const auto it = after.find(a.colmap_image_id);
    if (it == after.end()) continue;
    ++result->old_keyframes_kept;
    result->drift_max = std::max(result->drift_max, (a.pose.Center() - it->second->pose.Center()).norm());
    result->drift_rotation_max_deg = std::max(result->drift_rotation_max_deg, RotationAngleDeg(a.pose, it->second->pose));
  }
}

// Each old keyframe's observations before and after, and the share of its points the new session
// observed too; those that lost a quarter or more of their observations are the ones whose points
// no longer match (COLMAP's filters dropped them as the new frames and the bundle adjustment
// disagreed with them).
void MeasureSupport(const map::Map& old_map, const map::Map& extended, const std::string& session,
                    MapExtendResult* result) {
  const std::string prefix = session + "/";
  const auto is_new = [&](const map::Keyframe& k) { return k.name.rfind(prefix, 0) == 0; };
  std::vector<char> seen_by_new(extended.points.size(), 0), seen_by_old(extended.points.size(), 0);
  for (const map::Keyframe& k : extended.keyframes) {
    result->registered += is_new(k) ? 1 : 0;
    for (const map::KeyframeObservation& o : k.observations) (is_new(k) ? seen_by_new : seen_by_old)[o.point] = 1;
  }
  for (std::size_t p = 0; p < extended.points.size(); ++p)
    result->points_new_session_only += seen_by_new[p] && !seen_by_old[p] ? 1 : 0;
  const auto before = ById(old_map.keyframes);
  for (const map::Keyframe& k : extended.keyframes) {
    const auto it = before.find(k.colmap_image_id);
    if (is_new(k) || it == before.end()) continue;
    KeyframeSupport s{k.frame_index, k.name, static_cast<int>(it->second->observations.size()),
                      static_cast<int>(k.observations.size()), 0};
    int again = 0;
    for (const map::KeyframeObservation& o : k.observations) again += seen_by_new[o.point];
    s.seen_again = k.observations.empty() ? 0 : static_cast<double>(again) / static_cast<double>(k.observations.size());
    result->old_support.push_back(s);
    if (s.observations_after < 0.75 * s.observations_before) result->no_longer_match.push_back(s);
  }
}

json SupportJson(const std::vector<KeyframeSupport>& list) {
  json out = json::array();
  for (const KeyframeSupport& s : list)
    out.push_back({{"frame", s.frame_index}, {"name", s.name}, {"observations_before", s.observations_before},
                   {"observations_after", s.observations_after}, {"seen_again", s.seen_again}});
  return out;
}

std::string ExtendRecord(const MapExtendResult& r, const recordings::Recording& recording,
                         const MapExtendOptions& options) {
  const json j = {{"session", r.session},
                  {"recording", fs::absolute(recording.root).lexically_normal().string()},
                  {"frames", options.build.frames_spec},
                  {"selected_frames", r.selected_frames.size()},
                  {"registered", r.registered},
                  {"old_keyframes", r.old_keyframes},
                  {"old_keyframes_kept", r.old_keyframes_kept},
                  {"points_before", r.points_before},
                  {"points_after", r.points_after},
                  {"points_new_session_only", r.points_new_session_only},
                  {"drift_max", r.drift_max},
                  {"drift_rotation_max_deg", r.drift_rotation_max_deg},
                  {"path_extent", r.path_extent},
                  {"colmap_normalisation_scale", r.colmap_shift_scale},
                  {"sift",
                   {{"max_num_features", options.build.max_num_features},
                    {"max_num_orientations", options.build.max_num_orientations}}},
                  {"no_longer_match", SupportJson(r.no_longer_match)},
                  {"old_keyframes_support", SupportJson(r.old_support)}};
  return j.dump(2) + "\n";
}

void RenameInto(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw map::MapError(to.string() + ": cannot put the extended map's file in place (" + ec.message() + ")");
}

void AppendLog(const fs::path& from, const fs::path& to) {
  std::ifstream in(from);
  std::ofstream out(to, std::ios::app);
  out << in.rdbuf();
}

// The map folder takes the extension: the new frames' images, COLMAP's log, its database and
// model, the map's files, and map.arvmap last (each a rename, so that a file is either the old one
// or the new one whole). Signals only mark the cancellation token, and nothing here looks at it:
// once begun, the commit finishes.
void Commit(const fs::path& map_dir, const fs::path& work, const OldMap& old, const std::string& session,
            const std::string& record) {
  fs::create_directories(map_dir / "images");
  RenameInto(work / "images" / session, map_dir / "images" / session);
  AppendLog(work / "colmap.log", map_dir / "colmap.log");
  CheckpointDatabase(work / "database.db");
  CheckpointDatabase(old.database);  // its log (now empty) must not be replayed onto the new file
  std::error_code ec;
  for (const char* suffix : {"-wal", "-shm"}) fs::remove(old.database.string() + suffix, ec);
  RenameInto(work / "database.db", old.database);
  RenameInto(old.model_dir, work / "old-model");
  RenameInto(work / "model", old.model_dir);
  for (const char* name : {kMapCheckFileName, "keyframes.txt", "map.png"}) RenameInto(work / name, map_dir / name);
  WriteFileAtomically(map_dir / kExtendRecordName, record);
  RenameInto(work / map::kMapFileName, map_dir / map::kMapFileName);
  // `arview map`'s stage records describe the map before the extension: a re-run of it into
  // this folder would skip to a model its frames do not explain. Without them it builds afresh.
  fs::remove_all(map_dir / "stages", ec);
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Every keyframe's pose and every point moved by `s` (a similarity: reprojections unchanged).
void MoveIntoFrame(const Sim3& s, map::Map* map) {
  for (map::Keyframe& k : map->keyframes) k.pose = calib::Pose::FromRigid(s.TransformPose(k.pose.ToRigid()));
  for (map::MapPoint& p : map->points) p.xyz = s(p.xyz);
}

// The COLMAP camera id of the map's keyframes, which the new frames share.
std::int64_t MapCameraId(const OldMap& old, const std::vector<ColmapDatabase::ImageRow>& names) {
  const std::string& first = old.map.keyframes.front().name;
  const auto camera = std::find_if(names.begin(), names.end(), [&](const auto& n) { return n.name == first; });
  if (camera == names.end())
    throw map::MapError(old.database.string() + ": does not hold the map's keyframe '" + first +
                        "' (the database of another map?)");
  return camera->camera_id;
}

// The new frames' SIFT into the work folder's copy of the map's database, with the map's camera.
void ExtractNewFrames(const OldMap& old, const ImageSet& session, const calib::Camera& camera, std::int64_t camera_id,
                      const fs::path& work, const MapExtendOptions& options, const MapBuildCallbacks& cb) {
  const fs::path database = work / "database.db";
  CopyColmapDatabase(old.database, database);
  const fs::path list = work / "image_list.txt";
  std::string listed;
  for (const std::string& name : session.names) listed += name + "\n";
  WriteFileAtomically(list, listed);
  std::vector<std::string> args = ColmapExtractArgs(camera, options.build, database, session.root, list);
  args.insert(args.end(), {"--ImageReader.existing_camera_id", std::to_string(camera_id)});
  RunColmap(options.build, work, "extract", args, static_cast<int>(session.names.size()), cb);
}

// The extended model read as a map in the map file's frame, checked as a whole, with the old
// map's frame record, and what changed measured.
void ReadExtendedMap(const OldMap& old, const ImageSet& session, const std::optional<Sim3>& to_map_file,
                     const fs::path& work, const CancellationToken& cancel, MapExtendResult* result) {
  const fs::path database = work / "database.db";
  FrameLookup lookup = session.lookup;
  for (const map::Keyframe& k : old.map.keyframes) lookup[k.name] = {k.frame_index, k.timestamp};
  std::vector<std::vector<Eigen::Vector2f>> keypoints;
  map::Map model = ReadColmapMap(work / "model", database, lookup, cancel, &keypoints, false);
  if (to_map_file) MoveIntoFrame(*to_map_file, &model);
  result->check = CheckMap(model, keypoints, ReadTwoViewGeometries(database, model));
  result->map = CarryFrameRecord(old.map, std::move(model));
  result->points_after = result->map.points.size();
  MeasureDrift(old.map.keyframes, result->map, result);
  MeasureSupport(old.map, result->map, result->session, result);
}

// A failed COLMAP stage's error, its log moved from the work folder (removed) into the map's.
ColmapStageError WithMapLog(const ColmapStageError& e, const fs::path& work, const fs::path& map_dir) {
  AppendLog(work / "colmap.log", map_dir / "colmap.log");
  std::string message = e.what();
  const std::string work_log = (work / "colmap.log").string();
  if (const auto at = message.find(work_log); at != std::string::npos)
    message.replace(at, work_log.size(), (map_dir / "colmap.log").string());
  return ColmapStageError(message, e.stage, map_dir / "colmap.log", e.log_tail);
}

}  // namespace

std::optional<Sim3> MapFileFrameOfModel(const std::vector<map::Keyframe>& model_path, const map::Map& map_file) {
  const auto in_file = ById(map_file.keyframes);
  std::vector<Eigen::Vector3d> from, to;
  double apart = 0, turned = 0, extent = 0;
  for (const map::Keyframe& k : model_path) {
    const auto it = in_file.find(k.colmap_image_id);
    if (it == in_file.end()) continue;
    from.push_back(k.pose.Center());
    to.push_back(it->second->pose.Center());
    apart = std::max(apart, (from.back() - to.back()).norm());
    turned = std::max(turned, RotationAngleDeg(k.pose, it->second->pose));
  }
  for (const auto& a : to)
    for (const auto& b : to) extent = std::max(extent, (a - b).norm());
  if (from.empty()) throw map::MapError("map.arvmap holds none of the keyframes of COLMAP's model beside it");
  if (apart <= 1e-9 * std::max(extent, 1.0) && turned <= 1e-9) return std::nullopt;
  Sim3 s;
  try {
    s = EstimateSim3(from, to, true, "map.arvmap against COLMAP's model");
  } catch (const Error& e) {
    throw map::MapError(std::string(e.what()) + ": the map's frame cannot be told");
  }
  double off = 0;
  for (std::size_t i = 0; i < from.size(); ++i) off = std::max(off, (s(from[i]) - to[i]).norm());
  if (off > 1e-6 * std::max(extent, 1e-300))
    throw map::MapError("map.arvmap's keyframes are not COLMAP's model's moved by one similarity (" + std::to_string(off) +
                        " map units apart after the best): the map's frame cannot be told");
  return s;
}

std::optional<Sim3> RequireOwnModel(const fs::path& model_dir, const map::Map& map_file, const fs::path& map_dir) {
  const std::vector<map::Keyframe> model = ReadColmapCameraPath(model_dir);
  const auto in_model = ById(model);
  const std::string whose =
      model_dir.string() + ": not the COLMAP model of " + (map_dir / map::kMapFileName).string() + " (";
  for (const map::Keyframe& k : map_file.keyframes) {
    const auto it = in_model.find(k.colmap_image_id);
    if (it == in_model.end()) {
      throw map::MapError(whose + "its keyframe '" + k.name + "', COLMAP's image " + std::to_string(k.colmap_image_id) +
                          ", is not in the model): another map's model in this folder?");
    }
    if (it->second->name != k.name) {
      throw map::MapError(whose + "COLMAP's image " + std::to_string(k.colmap_image_id) + " is '" + it->second->name +
                          "' there and '" + k.name + "' in the map): another map's model in this folder?");
    }
  }
  try {
    return MapFileFrameOfModel(model, map_file);
  } catch (const map::MapError& e) {
    throw map::MapError(whose + e.what() + "): another map's model in this folder?");
  }
}

MapExtendResult ExtendMap(const fs::path& map_dir_arg, const recordings::Recording& recording,
                          const MapExtendOptions& options_arg, const MapBuildCallbacks& cb) {
  const fs::path map_dir = fs::absolute(map_dir_arg).lexically_normal();
  options_arg.build.Check(OptionNames().Nested("mapping"));
  const OldMap old = RequireExtendableMap(map_dir);
  RequireSameCamera(old.map.camera, recording, cb);
  if (FindExecutable(options_arg.build.colmap).empty())
    throw map::MapError("COLMAP not found: '" + options_arg.build.colmap + "' cannot be run (install COLMAP: apt-get install colmap)");
  MapExtendOptions options = options_arg;
  if (!options.max_features_set) TakeMapsSiftSettings(map_dir, &options.build);
  const std::optional<Sim3> to_map_file = RequireOwnModel(old.model_dir, old.map, map_dir);
  const auto names = ColmapDatabase(old.database, ColmapDatabase::Access::kRead).Images();
  const std::int64_t camera_id = MapCameraId(old, names);

  MapExtendResult result;
  result.session = NextSessionName(map_dir, names);
  result.old_keyframes = static_cast<int>(old.map.keyframes.size());
  result.points_before = old.map.points.size();
  const PartialFolder partial(map_dir / kExtendPartialName);
  const fs::path work = partial.dir();
  std::string stage = "select";
  auto t0 = std::chrono::steady_clock::now();
  const auto finish_stage = [&](const std::string& next) {
    result.timings.push_back({stage, Seconds(t0), false});
    stage = next;
    t0 = std::chrono::steady_clock::now();
  };
  try {
    const ImageSet selected = WithoutFramesInMap(
        SelectImages(recording, work / "select", options.build, cb, &result.selected_frames), old.map, map_dir,
        recording, cb, &result.selected_frames);
    if (selected.names.empty()) throw map::MapError("no frames of " + recording.root.string() + " to add");
    const ImageSet session = CopyIntoSession(selected, work / "images", result.session, options.build.cancel);
    finish_stage("extract");
    ExtractNewFrames(old, session, recording.camera, camera_id, work, options, cb);
    finish_stage("match");
    MatchPairs(PairsToMatch(old, session, work / "database.db", options), work / "database.db", work, options, cb);
    finish_stage("register");
    ContinueModel(old, session, work / "database.db", work, work / "continued", options, cb);
    RestoreMapFrame(old.model_dir, work / "continued", work / "model", &result);
    finish_stage("write");
    ReadExtendedMap(old, session, to_map_file, work, options.build.cancel, &result);
    if (result.registered == 0)
      throw map::MapError("COLMAP registered none of the " + std::to_string(session.names.size()) + " new frames of " +
                          recording.root.string() + " into the map (too few matches with it: another place, or too "
                          "little overlap with what the map holds); the map in " + map_dir.string() + " is as it was");
    MapBuildResult files;
    files.map = result.map;
    files.check = result.check;
    files.model_dir = work / "model";
    WriteMapFiles(files, work, options.build, cb);  // into the work folder; the commit moves them
    options.build.cancel.ThrowIfCancelled("the extension was not put in place");
  } catch (const ColmapStageError& e) {
    throw WithMapLog(e, work, map_dir);
  } catch (const CancelledError& e) {
    throw CancelledError("interrupted (" + SignalName(options.build.cancel.Signal()) + ") during the extension's " +
                             stage + " stage; the map in " + map_dir.string() + " is as it was",
                         e.signal_number());
  }
  Commit(map_dir, work, old, result.session, ExtendRecord(result, recording, options));
  finish_stage("");
  return result;
}

}  // namespace arview::mapping
