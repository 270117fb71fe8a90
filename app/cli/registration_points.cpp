#include "app/cli/registration_points.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "anim/character_bounds.h"
#include "anim_authoring/import.h"
#include "anim_authoring/scene.h"
#include "base/error.h"
#include "synth/synth_room.h"

namespace arview::app {

std::vector<Eigen::Vector3d> CharacterMarks(const anim::Character& character, const anim::Placement& placement) {
  const anim::RestBox box = anim::RestBoxOf(character);
  if (box.empty()) throw Error(character.source + ": the character has no vertices or joints to bound");
  const Eigen::Matrix4d to_map = placement.ModelToMap();
  std::vector<Eigen::Vector3d> marks{placement.anchor.position};
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d model((corner & 1) ? box.max.x() : box.min.x(), (corner & 2) ? box.max.y() : box.min.y(),
                                (corner & 4) ? box.max.z() : box.min.z());
    marks.push_back((to_map * model.homogeneous()).head<3>());
  }
  return marks;
}

std::vector<Eigen::Vector3d> SceneMarks(const std::filesystem::path& scene_file) {
  const authoring::Scene scene = authoring::LoadScene(scene_file);
  std::vector<Eigen::Vector3d> marks;
  for (const authoring::CharacterSpec& spec : scene.characters) {
    const std::vector<Eigen::Vector3d> own = CharacterMarks(authoring::LoadCharacter(spec.asset), spec.placement());
    marks.insert(marks.end(), own.begin(), own.end());
  }
  if (marks.empty()) throw Error(scene_file.string() + ": the scene has no character to project");
  return marks;
}

std::vector<Eigen::Vector3d> ReadPointsFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot read the points file");
  std::vector<Eigen::Vector3d> points;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string text = line.substr(0, line.find('#'));
    std::istringstream fields(text);
    Eigen::Vector3d p;
    std::string rest;
    if (!(fields >> std::ws) || fields.eof()) continue;  // blank or comment
    if (!(fields >> p.x() >> p.y() >> p.z()) || (fields >> rest) || !p.allFinite()) {
      throw Error(file.string() + ":" + std::to_string(number) + ": expected three numbers x y z, got '" + line + "'");
    }
    points.push_back(p);
  }
  if (points.empty()) throw Error(file.string() + ": holds no points (x y z a line)");
  return points;
}

std::vector<Eigen::Vector3d> RoomGeometryPoints(const std::filesystem::path& groundtruth,
                                                const std::filesystem::path& photos) {
  std::ifstream in(groundtruth);
  std::string header;
  if (!in || !std::getline(in, header)) throw Error(groundtruth.string() + ": cannot read the ground truth");
  if (header.rfind("# arview synth room", 0) != 0) {
    throw Error(groundtruth.string() + ": not the ground truth of a room rendered by 'arview synth room' (its first "
                "line says so); --room-points needs that room's geometry");
  }
  const synth::SynthLighting light =
      header.find("window light") != std::string::npos ? synth::SynthLighting::kWindow : synth::SynthLighting::kEven;
  std::vector<Eigen::Vector3d> points;
  for (const synth::RoomPanel& panel : synth::MakeRoomScene(photos, light).panels) {
    const Eigen::Vector3d* c = panel.corners;
    for (int k = 0; k < 4; ++k) {
      points.push_back(c[k]);
      points.push_back(0.5 * (c[k] + c[(k + 1) % 4]));
    }
    points.push_back(0.25 * (c[0] + c[1] + c[2] + c[3]));
  }
  return points;
}

}  // namespace arview::app
