#include "app/placement/scene_lighting.h"

#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <cmath>

#include "base/error.h"
#include "base/image_file.h"
#include "render/offscreen.h"
#include "room/scene_proxy.h"

namespace arview::app {

namespace fs = std::filesystem;

fs::path LightFileFor(const fs::path& scene_file) {
  fs::path light = scene_file;
  light.replace_extension(".light.yml");
  return light;
}

std::optional<PlacedLightReport> EstimatePlacedLight(const map::Map& map, const fs::path& map_dir,
                                                     const fs::path& recording_root, const ScenePlacement& placed,
                                                     int max_keyframes) {
  if (map.keyframes.empty() || map.points.size() < 3) return std::nullopt;
  auto image_path = [&](const map::Keyframe& k) -> fs::path {
    if (const fs::path p = map_dir / "images" / k.name; fs::exists(p)) return p;
    if (!recording_root.empty()) {
      if (const fs::path p = recording_root / k.name; fs::exists(p)) return p;
    }
    return {};
  };
  std::vector<room::LightKeyframe> keys;
  const size_t n = map.keyframes.size();
  const size_t take = std::min<size_t>(n, static_cast<size_t>(std::max(1, max_keyframes)));
  for (size_t i = 0; i < take; ++i) {
    const map::Keyframe& k = map.keyframes[i * n / take];
    const fs::path path = image_path(k);
    if (path.empty()) continue;
    cv::Mat image;
    try {
      image = ReadImageFile(path, cv::IMREAD_COLOR);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (a keyframe image, for the lighting)");
    }
    if (image.cols != map.camera.width || image.rows != map.camera.height) {
      throw Error(path.string() + ": keyframe image is " + std::to_string(image.cols) + "x" +
                         std::to_string(image.rows) + ", the map's camera " + std::to_string(map.camera.width) + "x" +
                         std::to_string(map.camera.height));
    }
    keys.push_back({map.camera, k.pose, std::move(image)});
  }
  if (keys.empty()) return std::nullopt;

  const auto start = std::chrono::steady_clock::now();
  std::vector<Eigen::Vector3d> points;
  points.reserve(map.points.size());
  for (const auto& p : map.points) points.push_back(p.xyz);
  room::SceneProxy proxy = room::BuildPlaneProxy(points);
  const room::TriangleBvh scene(proxy.Triangles());
  const Anchor& anchor = placed.anchor;
  const Eigen::Vector3d up = (anchor.rotation * Eigen::Vector3d::UnitY()).normalized();
  const double height = placed.rest_height * anchor.scale;
  // The floor the character stands on cannot hide it: out of the occluders (its inlier band
  // is a hundredth of the character's height, or of the plane proxy's own tolerance).
  room::SceneProxy occluders = proxy;
  occluders.RemovePlane(up, -up.dot(anchor.position), 10.0, std::max(0.05 * height, 1e-9));
  const double proxy_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  PlacedLightReport report;
  report.light = room::EstimateRoomLight(keys, scene, anchor.position + 0.5 * height * up);
  report.light.occluder_triangles = occluders.Triangles();
  report.keyframes_used = static_cast<int>(keys.size());
  report.proxy_patches = static_cast<int>(proxy.patches.size());
  report.occluder_triangles = static_cast<int>(report.light.occluder_triangles.size() / 3);
  report.proxy_seconds = proxy_seconds;
  return report;
}

void WritePlacedLight(const map::Map& map, const fs::path& map_dir, const fs::path& recording_root,
                      const ScenePlacement& placed, const fs::path& scene_file) {
  if (!recording_root.empty() && !fs::is_directory(recording_root)) {
    throw Error(recording_root.string() + ": --recording is not a folder");
  }
  std::optional<PlacedLightReport> report;
  try {
    report = EstimatePlacedLight(map, map_dir, recording_root, placed);
  } catch (const room::LightError& e) {
    throw Error(e.what());
  }
  if (!report) {
    std::printf("no room light: no keyframe image found in %s/images%s (give --recording)\n", map_dir.string().c_str(),
                recording_root.empty() ? "" : (" or " + recording_root.string()).c_str());
    return;
  }
  const fs::path file = LightFileFor(scene_file);
  try {
    room::SaveRoomLight(report->light, file);
  } catch (const std::exception& e) {
    throw Error(e.what());
  }
  const room::RoomLight& l = report->light;
  const room::DominantLight& d = l.dominant;
  std::printf("wrote %s: light from %d keyframes (%.0f%% of directions seen), dominant light towards (%.3f, %.3f, %.3f), "
              "colour (%.3f %.3f %.3f), ambient (%.3f %.3f %.3f); scene proxy %d planes, %d occluder triangles; "
              "%.2f s (proxy %.2f s)\n",
              file.string().c_str(), report->keyframes_used, 100 * l.seen_fraction, d.direction.x(), d.direction.y(),
              d.direction.z(), d.color.x(), d.color.y(), d.color.z(), d.ambient.x(), d.ambient.y(), d.ambient.z(),
              report->proxy_patches, report->occluder_triangles, l.seconds + report->proxy_seconds, report->proxy_seconds);
}

SceneLighting ResolveSceneLighting(const fs::path& scene_file, const std::string& lighting, const fs::path& light_file) {
  SceneLighting out;
  out.file = !light_file.empty() ? light_file : (scene_file.empty() ? fs::path() : LightFileFor(scene_file));
  const bool available = !out.file.empty() && fs::exists(out.file);
  if (lighting == "auto") {
    out.mode = available ? render::LightingMode::kShShadowed : render::LightingMode::kFixed;
  } else {
    try {
      out.mode = render::ParseLightingMode(lighting);
    } catch (const render::RenderError& e) {
      throw Error(std::string("--lighting: ") + e.what());
    }
  }
  if (!light_file.empty() && !fs::exists(light_file)) throw Error(light_file.string() + ": --light file not found");
  if (out.mode != render::LightingMode::kFixed && !available) {
    throw Error("--lighting " + lighting + " needs the room's light: " +
                       (out.file.empty() ? std::string("no scene") : out.file.string()) +
                       " is missing (arview place writes it when it finds the keyframe images; see --recording)");
  }
  if (available && (out.mode != render::LightingMode::kFixed || lighting == "auto")) {
    try {
      out.light = room::LoadRoomLight(out.file);
    } catch (const room::LightError& e) {
      throw Error(e.what());
    }
  }
  return out;
}

}  // namespace arview::app
