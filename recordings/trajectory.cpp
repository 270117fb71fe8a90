#include "recordings/trajectory.h"

#include "base/library_errors.h"

#include "base/atomic_file.h"
#include "base/input_guard.h"
#include "base/point_spread.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

namespace arview::recordings {

std::string ReadRecordingText(const std::filesystem::path& file) {
  try {
    return ReadFileUpTo(file, kMaxTextFileBytes);
  } catch (const InputError& e) {
    throw RecordingError(e.what());
  }
}

namespace {

Trajectory ReadTumFile(const std::filesystem::path& path) {
  std::istringstream in(ReadRecordingText(path));
  Trajectory out;
  std::map<double, std::pair<int, std::size_t>> first_at;  // timestamp → its first line, its pose
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    double v[8];
    for (double& x : v) {
      if (!(ss >> x) || !std::isfinite(x)) {
        throw RecordingError(path.string() + ":" + std::to_string(line_no) +
                             ": expected 'timestamp tx ty tz qx qy qz qw'");
      }
    }
    std::string extra;
    if (ss >> extra) {
      throw RecordingError(path.string() + ":" + std::to_string(line_no) + ": unexpected '" + extra +
                           "' after 'timestamp tx ty tz qx qy qz qw'");
    }
    const Eigen::Quaterniond q_wc(v[7], v[4], v[5], v[6]);
    if (std::abs(q_wc.norm() - 1.0) > 1e-3) {
      throw RecordingError(path.string() + ":" + std::to_string(line_no) +
                           ": quaternion is not of unit length");
    }
    // Beyond kMaxPositionNorm the squares of every error overflow (eval printed an ATE of inf).
    if (Eigen::Vector3d(v[1], v[2], v[3]).norm() > kMaxPositionNorm) {
      std::ostringstream message;
      message << path.string() << ":" << line_no << ": the position (" << v[1] << ", " << v[2] << ", " << v[3]
              << ") lies beyond " << kMaxPositionNorm << " of the origin";
      throw RecordingError(message.str());
    }
    out.push_back({v[0], calib::Pose::FromCameraToWorld(q_wc, {v[1], v[2], v[3]})});
    // Two poses at one time: the association would keep one of them and drop the other unsaid.
    const auto [earlier_at, inserted] = first_at.emplace(v[0], std::make_pair(line_no, out.size() - 1));
    if (!inserted) {
      const calib::Pose& earlier = out[earlier_at->second.second].pose;
      if (earlier.q_cw.coeffs() != out.back().pose.q_cw.coeffs() || earlier.t_cw != out.back().pose.t_cw) {
        std::ostringstream message;
        message << path.string() << ":" << line_no << ": a second pose at the time " << std::setprecision(17) << v[0]
                << " s, another than line " << earlier_at->second.first << "'s: one time, one pose";
        throw RecordingError(message.str());
      }
      out.pop_back();  // the same pose again: kept once
    }
  }
  return out;
}

}  // namespace

Trajectory ReadTum(const std::filesystem::path& path) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<RecordingError>(path.string(), [&] { return ReadTumFile(path); });
}

namespace {

std::string TumHeader(const std::string& header_comment) {
  std::string header = header_comment.empty() ? "" : "# " + header_comment + "\n";
  return header + "# timestamp tx ty tz qx qy qz qw (camera-to-world)\n";
}

std::string TumLine(const StampedPose& p) {
  const Eigen::Vector3d c = p.pose.Center();
  const Eigen::Quaterniond q = p.pose.CameraToWorldRotation();
  std::ostringstream out;
  out << std::setprecision(9) << std::fixed << p.timestamp << std::defaultfloat << std::setprecision(17) << ' '
      << c.x() << ' ' << c.y() << ' ' << c.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w()
      << '\n';
  return out.str();
}

}  // namespace

void WriteTum(const Trajectory& trajectory, const std::filesystem::path& path,
              const std::string& header_comment) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << TumHeader(header_comment);
    for (const StampedPose& p : trajectory) out << TumLine(p);
  });
}

TumFileWriter::TumFileWriter(const std::filesystem::path& path, const std::string& header_comment)
    : file_(path, "the trajectory") {
  file_.Write(TumHeader(header_comment));
}

void TumFileWriter::Add(const StampedPose& pose) {
  file_.Write(TumLine(pose));
  ++poses_;
}

}  // namespace arview::recordings
