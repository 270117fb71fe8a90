#include "app/cli/first_run_figure.h"

#include <cstdio>

#include "app/placement/place_character.h"
#include "map/map_file.h"

namespace arview::app {

namespace {

constexpr const char* kFigure = "builtin:figure";

std::string PointText(const Eigen::Vector3d& p, const char* separator) {
  char text[128];
  std::snprintf(text, sizeof text, "%.4f%s%.4f%s%.4f", p.x(), separator, p.y(), separator, p.z());
  return text;
}

}  // namespace

std::optional<FirstViewCharacter> FirstRunFigure(const map::Map& map, const std::string& map_dir) {
  ScenePlacement placed;
  try {
    if (const auto why = map::DegeneratePoints(map)) throw PlacementError("the map's points cannot hold a floor: " + *why);
    placed = PlaceCharacter(map, kFigure, PlaceCharacterOptions{});
  } catch (const PlacementError& e) {
    std::fprintf(stderr, "note: no --scene, and %s has no floor for the built-in figure (%s): the session goes on "
                         "with the video and the tracking only\n",
                 map_dir.c_str(), e.what());
    return std::nullopt;
  }
  FirstViewCharacter figure;
  figure.scene = authoring::ParseScene(SceneYaml(placed), std::string(kFigure) + " placed on " + map_dir);
  const Anchor on_floor = placed.anchor;
  const double height = placed.anchor.scale * placed.rest_height;  // map units
  figure.stand_in_front_of = [on_floor, height](const calib::Pose& view) {
    return StandInFrontOfView(on_floor, height, view.Center(), view.CameraToWorldRotation() * Eigen::Vector3d::UnitZ());
  };
  figure.on_placed = [&map, map_dir](const Anchor& anchor, const calib::Pose& view, double milliseconds) {
    std::fprintf(stderr, "\n%s\n", FirstRunFigureLine(map, map_dir, anchor, view, milliseconds).c_str());
  };
  return figure;
}

std::string FirstRunFigureLine(const map::Map& map, const std::string& map_dir, const Anchor& anchor,
                               const calib::Pose& view, double milliseconds) {
  const Eigen::Vector3d up = anchor.rotation * Eigen::Vector3d::UnitY();
  Eigen::Vector3d along_floor = view.Center() - anchor.position;
  along_floor -= along_floor.dot(up) * up;
  const char* unit = map.frame.metric() ? "m" : "map units";
  char where[160];
  std::snprintf(where, sizeof where, ") %s, %.2f %s along the floor in front of the first localized view (placed in %.2f ms)",
                unit, along_floor.norm(), unit, milliseconds);
  return "no --scene: the built-in figure stands on the floor of " + map_dir + " at (" + PointText(anchor.position, ", ") +
         where + "; to keep it: arview place " + map_dir + " --character " + kFigure + " --at " +
         PointText(anchor.position, ",") + " --facing " + PointText(view.Center(), ",") + " --out scene.yaml";
}

}  // namespace arview::app
