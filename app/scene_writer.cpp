#include "app/scene_writer.h"

#include <cstdio>
#include <sstream>

#include <Eigen/Geometry>

#include "anim/scene.h"
#include "app/output_file.h"

namespace arview::app {

namespace {

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

// Double-quoted so that a path holding " #" or ": " reads back as written.
std::string Quoted(const std::string& text) {
  std::string q = "\"";
  for (char ch : text) {
    if (ch == '"' || ch == '\\') q += '\\';
    q += ch;
  }
  return q + "\"";
}

}  // namespace

std::string SceneYaml(const PlacedCharacter& c) {
  const Eigen::Quaterniond q(c.anchor.rotation);
  std::ostringstream y;
  if (!c.comment.empty()) y << "# " << c.comment << "\n";
  y << "# Written by 'arview place'; edit freely (format: docs/anim.md).\n";
  y << "characters:\n";
  y << "  - name: " << c.name << "\n";
  y << "    asset: " << Quoted(c.asset.string()) << "\n";
  y << "    scale: 1\n";
  y << "    anchor:\n";
  y << "      position: [" << Num(c.anchor.position.x()) << ", " << Num(c.anchor.position.y()) << ", "
    << Num(c.anchor.position.z()) << "]\n";
  y << "      rotation: [" << Num(q.x()) << ", " << Num(q.y()) << ", " << Num(q.z()) << ", " << Num(q.w()) << "]\n";
  y << "      scale: " << Num(c.anchor.scale) << "\n";
  y << "    weights: {mode: inverse-distance, distance: geodesic, alpha: 3}\n";
  y << "    blend: {method: dlb, precision: 0.001, max_iterations: 32}\n";
  if (!c.base_clip.empty()) {
    y << "    lookat:\n";
    y << "      base_clip: " << c.base_clip << "\n";
  }
  y << "    keys:\n";
  for (int k = 0; k < c.key_count; ++k) {
    y << "      - azimuth: " << Num(360.0 * k / c.key_count) << "\n";
    y << "        elevation: " << Num(c.key_elevation_deg) << "\n";
    y << "        generate: lookat\n";
  }
  return y.str();
}

void WriteSceneFile(const PlacedCharacter& c, const std::filesystem::path& file) {
  const std::string text = SceneYaml(c);
  anim::ParseScene(text, file);  // throws anim::Error when the text would not load
  WriteTextFileAtomically(file, text);
}

}  // namespace arview::app
