#include "app/view/view_authoring.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "app/view/view_animation.h"

namespace arview::app {

namespace {

constexpr double kDeg = M_PI / 180;

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < text.size()) {
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

int Indent(const std::string& line) {
  const size_t i = line.find_first_not_of(' ');
  return i == std::string::npos ? static_cast<int>(line.size()) : static_cast<int>(i);
}

// Blank, or only a comment.
bool Inert(const std::string& line) {
  const size_t i = line.find_first_not_of(" \t\r");
  return i == std::string::npos || line[i] == '#';
}

std::string Content(const std::string& line) { return line.substr(static_cast<size_t>(Indent(line))); }

bool StartsItem(const std::string& line) {
  const std::string c = Content(line);
  return c == "-" || c.rfind("- ", 0) == 0;
}

std::string Number(double v) {
  char t[32];
  std::snprintf(t, sizeof t, "%.4f", v);
  std::string s = t;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

// The YAML of one key, as an item of a block sequence at `indent`.
std::vector<std::string> KeyText(const authoring::KeySpec& key, const authoring::CharacterSpec& spec, int indent) {
  const Eigen::Vector2d ae = AzimuthElevation(key.viewpoint, spec.forward, spec.up);
  const std::string pad(static_cast<size_t>(indent), ' ');
  std::vector<std::string> out{pad + "- azimuth: " + Number(ae.x()), pad + "  elevation: " + Number(ae.y())};
  switch (key.source) {
    case authoring::KeySpec::Source::kClip: out.push_back(pad + "  clip: \"" + key.clip + "\""); break;
    case authoring::KeySpec::Source::kLookAt:
      // A gesture key is a look-at key with the arm on top: saving must keep its gesture.
      if (key.gesture != authoring::Gesture::kNone) out.push_back(pad + "  gesture: " + ToString(key.gesture));
      else out.push_back(pad + "  generate: lookat");
      break;
    case authoring::KeySpec::Source::kRestPose: out.push_back(pad + "  pose: rest"); break;
    case authoring::KeySpec::Source::kStaticPose:
      out.push_back(pad + "  pose: \"" + key.clip + "@" + Number(key.pose_time) + "\"");
      break;
  }
  return out;
}

int LineOf(const std::string& where) {
  const size_t colon = where.rfind(':');
  if (colon == std::string::npos) return 0;
  try {
    return std::stoi(where.substr(colon + 1));
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

std::vector<KeyChoice> KeyChoices(const anim::Character& asset) {
  std::vector<KeyChoice> choices;
  for (const anim::Clip& clip : asset.clips) {
    choices.push_back({authoring::KeySpec::Source::kClip, clip.name, "clip " + clip.name});
  }
  choices.push_back({authoring::KeySpec::Source::kLookAt, "", "generate lookat"});
  choices.push_back({authoring::KeySpec::Source::kRestPose, "", "pose rest"});
  for (const anim::Clip& clip : asset.clips) {
    choices.push_back({authoring::KeySpec::Source::kStaticPose, clip.name, "pose " + clip.name + "@now"});
  }
  return choices;
}

authoring::KeySpec MakeKey(const Eigen::Vector3d& viewpoint, const KeyChoice& choice, const anim::Character& asset,
                      const authoring::CharacterSpec& spec, double time) {
  authoring::KeySpec key;
  const Eigen::Vector2d ae = AzimuthElevation(viewpoint, spec.forward, spec.up);
  auto hundredths = [](double deg) { return std::floor(deg * 100 + 0.5) / 100; };
  key.viewpoint = anim::DirectionFromAzimuthElevation(hundredths(ae.x()), hundredths(ae.y()), spec.forward, spec.up);
  key.source = choice.source;
  key.clip = choice.clip;
  if (choice.source == authoring::KeySpec::Source::kStaticPose) {
    const anim::Clip* clip = asset.FindClip(choice.clip);
    const double duration = clip ? clip->duration : 0;
    double t = duration > 0 ? std::fmod(std::max(0.0, time), duration) : 0;
    t = std::floor(t * 100 + 0.5) / 100;
    key.pose_time = std::min(t, duration);
  }
  return key;
}

Eigen::Vector2d AzimuthElevation(const Eigen::Vector3d& direction, const Eigen::Vector3d& forward,
                                 const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  Eigen::Vector3d f = forward - forward.dot(u) * u;
  if (f.norm() < 1e-12) f = u.unitOrthogonal();
  f.normalize();
  const Eigen::Vector3d left = u.cross(f);
  const Eigen::Vector3d d = direction.normalized();
  const double elevation = std::asin(std::clamp(d.dot(u), -1.0, 1.0)) / kDeg;
  const double azimuth = std::atan2(d.dot(left), d.dot(f)) / kDeg;
  return {azimuth, elevation};
}

KeyEditor::KeyEditor(std::vector<authoring::KeySpec> keys) : keys_(std::move(keys)) {
  for (size_t i = 0; i < keys_.size(); ++i) keys_ids_.push_back(next_id_++);
  saved_ids_ = keys_ids_;
}

std::vector<int> KeyEditor::FileOrigins() const {
  std::vector<int> origins;
  for (int id : keys_ids_) {
    const auto it = std::find(saved_ids_.begin(), saved_ids_.end(), id);
    origins.push_back(it == saved_ids_.end() ? -1 : static_cast<int>(it - saved_ids_.begin()));
  }
  return origins;
}

void KeyEditor::Add(const authoring::KeySpec& key) {
  history_.push_back({keys_, keys_ids_});
  keys_.push_back(key);
  keys_ids_.push_back(next_id_++);
}

void KeyEditor::Remove(int index) {
  if (index < 0 || index >= static_cast<int>(keys_.size())) throw std::runtime_error("no key " + std::to_string(index));
  if (keys_.size() == 1) throw std::runtime_error("the last key cannot be removed: a character needs one key");
  history_.push_back({keys_, keys_ids_});
  keys_.erase(keys_.begin() + index);
  keys_ids_.erase(keys_ids_.begin() + index);
}

bool KeyEditor::Undo() {
  if (history_.empty()) return false;
  keys_ = std::move(history_.back().keys);
  keys_ids_ = std::move(history_.back().ids);
  history_.pop_back();
  return true;
}

void KeyEditor::MarkSaved() { saved_ids_ = keys_ids_; }

int KeyEditor::Nearest(const Eigen::Vector3d& viewpoint) const {
  int best = -1;
  double best_angle = 1e300;
  for (size_t k = 0; k < keys_.size(); ++k) {
    const Eigen::Vector3d& d = keys_[k].viewpoint;
    const double angle = std::atan2(d.cross(viewpoint).norm(), d.dot(viewpoint));
    if (angle < best_angle) best_angle = angle, best = static_cast<int>(k);
  }
  return best;
}

std::string SpliceKeys(const std::string& text, const authoring::Scene& scene, int character,
                       const std::vector<authoring::KeySpec>& keys, const std::vector<int>& origins) {
  const std::string file = scene.file.string();
  const authoring::CharacterSpec& spec = scene.characters.at(static_cast<size_t>(character));
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(file + ": cannot write the keys of character '" + spec.name + "': " + why);
  };
  const std::vector<std::string> lines = SplitLines(text);
  const int n = static_cast<int>(lines.size());
  const int item = LineOf(spec.where) - 1;  // the character's `- name: ...` line
  if (item < 0 || item >= n || !StartsItem(lines[item])) fail("its entry is not a block sequence item");
  // The character's keys sit at the indentation of the text after its dash.
  const std::string& dash_line = lines[item];
  const int fields = static_cast<int>(dash_line.find_first_not_of(' ', static_cast<size_t>(Indent(dash_line)) + 1));
  if (fields <= 0) fail("its entry does not start on the dash's line");
  int keys_line = -1;
  for (int i = item; i < n && keys_line < 0; ++i) {
    if (i > item && !Inert(lines[i]) && Indent(lines[i]) < fields) break;  // the next character
    const std::string field = i == item ? dash_line.substr(static_cast<size_t>(fields)) : lines[i];
    if ((i == item || Indent(lines[i]) == fields) && Content(field).rfind("keys:", 0) == 0) keys_line = i;
  }
  if (keys_line < 0) fail("no 'keys:' line found");
  std::string after = Content(lines[keys_line]).substr(5);
  if (const size_t hash = after.find('#'); hash != std::string::npos) after.resize(hash);
  if (after.find_first_not_of(" \t\r") != std::string::npos) fail("they are written in flow style; write them as a block list");
  // The block: the lines after `keys:` deeper than the fields, or items at the fields' column.
  int end = keys_line + 1;
  for (int i = keys_line + 1; i < n; ++i) {
    if (Inert(lines[i])) continue;
    const int indent = Indent(lines[i]);
    if (indent > fields || (indent == fields && StartsItem(lines[i]))) end = i + 1;
    else break;
  }
  std::vector<int> starts;
  int item_indent = -1;
  for (int i = keys_line + 1; i < end; ++i) {
    if (Inert(lines[i])) continue;
    if (item_indent < 0) {
      if (!StartsItem(lines[i])) fail("the keys are not a block list");
      item_indent = Indent(lines[i]);
    }
    if (Indent(lines[i]) == item_indent && StartsItem(lines[i])) starts.push_back(i);
  }
  if (starts.size() != spec.keys.size()) {
    fail("found " + std::to_string(starts.size()) + " key entries in the text but the reader found " +
         std::to_string(spec.keys.size()));
  }
  if (item_indent < 0) item_indent = fields + 2;

  std::vector<std::string> out(lines.begin(), lines.begin() + (starts.empty() ? end : starts.front()));
  for (size_t k = 0; k < keys.size(); ++k) {
    const int origin = k < origins.size() ? origins[k] : -1;
    if (origin >= 0 && origin < static_cast<int>(starts.size())) {
      const int from = starts[origin];
      const int to = origin + 1 < static_cast<int>(starts.size()) ? starts[origin + 1] : end;
      out.insert(out.end(), lines.begin() + from, lines.begin() + to);
    } else {
      const std::vector<std::string> added = KeyText(keys[k], spec, item_indent);
      out.insert(out.end(), added.begin(), added.end());
    }
  }
  out.insert(out.end(), lines.begin() + end, lines.end());
  std::string result;
  for (const std::string& l : out) result += l + "\n";
  return result;
}

authoring::Scene ValidateSceneText(const std::string& text, const std::filesystem::path& file, int character,
                              const std::vector<authoring::KeySpec>& keys) {
  authoring::Scene scene;
  try {
    scene = authoring::ParseScene(text, file);
  } catch (const anim::Error& e) {
    throw std::runtime_error(std::string("the edited scene does not read back (not written): ") + e.what());
  }
  const std::vector<authoring::KeySpec>& got = scene.characters.at(static_cast<size_t>(character)).keys;
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(file.string() + ": the edited scene reads back with " + why + " (not written)");
  };
  if (got.size() != keys.size()) fail(std::to_string(got.size()) + " keys instead of " + std::to_string(keys.size()));
  for (size_t k = 0; k < keys.size(); ++k) {
    const double angle = std::atan2(got[k].viewpoint.cross(keys[k].viewpoint).norm(), got[k].viewpoint.dot(keys[k].viewpoint));
    if (angle > 1e-6) fail("key " + std::to_string(k) + " moved by " + std::to_string(angle / kDeg) + " deg");
    if (KeySourceLabel(got[k]) != KeySourceLabel(keys[k])) {
      fail("key " + std::to_string(k) + " playing " + KeySourceLabel(got[k]) + " instead of " + KeySourceLabel(keys[k]));
    }
  }
  return scene;
}

}  // namespace arview::app
