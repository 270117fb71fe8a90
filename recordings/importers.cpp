#include "recordings/importers.h"

#include "recordings/image_metadata.h"

#include "base/image_file.h"
#include "base/input_guard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <Eigen/SVD>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "recordings/recording.h"

namespace arview::recordings {

namespace fs = std::filesystem;

namespace {

std::string At(const fs::path& file, int line_no) { return file.string() + ":" + std::to_string(line_no); }

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool IsImageFile(const fs::path& p) {
  static const std::vector<std::string> kExt = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm"};
  const std::string ext = Lower(p.extension().string());
  return std::find(kExt.begin(), kExt.end(), ext) != kExt.end();
}

void RequireDirectory(const fs::path& dir, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw RecordingError(dir.string() + ": " + what + " does not exist");
  if (!fs::is_directory(dir, ec)) throw RecordingError(dir.string() + ": " + what + " is not a folder");
}

std::string FrameName(size_t index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06zu.png", index);
  return buf;
}

// Reads a source image (throws naming it) and returns its size.
cv::Mat ReadSourceImage(const fs::path& file) {
  try {
    return ReadImageFile(file, cv::IMREAD_UNCHANGED);
  } catch (const Error& e) {
    throw RecordingError(e.what());
  }
}

// Stores one source image as frames/<index>.png: PNG files are copied byte for byte (no
// re-encoding), others are decoded and written as PNG.
void StoreFrame(const fs::path& source, const cv::Mat& decoded, const fs::path& out_dir, size_t index,
                std::vector<FrameEntry>* frames, double timestamp) {
  const std::string rel = "frames/" + FrameName(index);
  const fs::path dest = out_dir / rel;
  if (Lower(source.extension().string()) == ".png") {
    std::error_code ec;
    fs::copy_file(source, dest, fs::copy_options::overwrite_existing, ec);
    if (ec) throw RecordingError(dest.string() + ": cannot copy " + source.string() + " (" + ec.message() + ")");
  } else {
    WriteImageAtomically(dest, decoded);
  }
  frames->push_back({timestamp, rel});
}

void CheckSize(const cv::Mat& image, const fs::path& file, const calib::Camera& camera, const std::string& camera_source) {
  if (image.cols != camera.width || image.rows != camera.height) {
    throw RecordingError(file.string() + ": image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                         " but " + camera_source + " is " + std::to_string(camera.width) + "x" +
                         std::to_string(camera.height));
  }
}

// Copies a list of still images as frames 0..n-1 with timestamp = index (seconds). Every image
// must have the camera's size.
std::vector<FrameEntry> StoreStills(const std::vector<fs::path>& images, const fs::path& out_dir,
                                    const calib::Camera& camera, const std::string& camera_source) {
  std::vector<FrameEntry> frames;
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat image = ReadSourceImage(images[i]);
    CheckSize(image, images[i], camera, camera_source);
    StoreFrame(images[i], image, out_dir, i, &frames, static_cast<double>(i));
  }
  return frames;
}

// The recording folder an import writes into: prepared (PrepareRecordingFolder: created, or an
// old recording cleared with --force) on construction; unless Commit() is called after the last
// file is written, the destructor removes everything the import wrote (frames/, camera.yaml,
// groundtruth.txt, frames.txt) and the folder itself if the import created it. Issue 17: an
// import that failed on a full disk left frames/000000.png (0 bytes) behind.
class PreparedOutput {
 public:
  PreparedOutput(const fs::path& out_dir, bool overwrite) : out_dir_(out_dir) {
    std::error_code ec;
    existed_ = fs::exists(out_dir, ec);
    PrepareRecordingFolder(out_dir, overwrite);  // throws before touching a folder that is not ours
  }
  PreparedOutput(const PreparedOutput&) = delete;
  PreparedOutput& operator=(const PreparedOutput&) = delete;
  ~PreparedOutput() {
    if (committed_) return;
    std::error_code ec;
    for (const char* name : {"frames.txt", "camera.yaml", "groundtruth.txt"}) fs::remove(out_dir_ / name, ec);
    fs::remove_all(out_dir_ / "frames", ec);
    if (!existed_) fs::remove(out_dir_, ec);  // only if empty: nothing else was there
  }
  void Commit() { committed_ = true; }

 private:
  fs::path out_dir_;
  bool existed_ = false;
  bool committed_ = false;
};

ImportResult Finish(const fs::path& out_dir, const calib::Camera& camera, const std::vector<FrameEntry>& frames,
                    const Trajectory* groundtruth, std::vector<std::string> notes) {
  try {
    calib::SaveCamera(camera, out_dir / "camera.yaml");
  } catch (const calib::CameraError& e) {
    throw RecordingError(e.what());
  }
  if (groundtruth) WriteTum(*groundtruth, out_dir / "groundtruth.txt", "ground truth, imported by arview");
  WriteFramesTxt(out_dir, frames);
  ImportResult r;
  r.frame_count = static_cast<int>(frames.size());
  r.has_groundtruth = groundtruth != nullptr;
  r.camera = camera;
  r.notes = std::move(notes);
  return r;
}

// The rotation nearest to M (SVD); throws when M is not within `tolerance` of a rotation.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& M, double tolerance, const std::string& where) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0 || (R - M).cwiseAbs().maxCoeff() > tolerance) {
    throw RecordingError(where + ": the rotation matrix is not a rotation (not orthonormal with determinant +1)");
  }
  return R;
}

std::vector<fs::path> ImagesInFolder(const fs::path& dir) {
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  if (images.empty()) throw RecordingError(dir.string() + ": holds no image files (png, jpg, bmp, tif, ppm, pgm)");
  return images;
}

// ---------------------------------------------------------------- Middlebury

struct MiddleburyView {
  std::string name;
  Eigen::Matrix3d K;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  int line_no = 0;
};

fs::path FindParFile(const fs::path& dir) {
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    // Any kind of entry: a FIFO or a device so named is refused by name when read, not overlooked.
    if (!entry.is_directory() && name.size() > 8 && name.ends_with("_par.txt")) found.push_back(entry.path());
  }
  if (found.empty()) throw RecordingError(dir.string() + ": no *_par.txt camera file (not a Middlebury folder)");
  if (found.size() > 1) {
    throw RecordingError(dir.string() + ": holds several *_par.txt files (" + found[0].filename().string() + ", " +
                         found[1].filename().string() + "); import one data set per folder");
  }
  return found[0];
}

std::vector<MiddleburyView> ReadParFile(const fs::path& file) {
  std::istringstream in(ReadRecordingText(file));
  std::vector<MiddleburyView> views;
  std::string line;
  int line_no = 0;
  long declared = -1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ss(line);
    if (declared < 0) {
      if (!(ss >> declared) || declared <= 0) throw RecordingError(At(file, line_no) + ": expected the image count");
      continue;
    }
    MiddleburyView v;
    v.line_no = line_no;
    double x[21];
    if (!(ss >> v.name)) throw RecordingError(At(file, line_no) + ": expected an image name");
    for (double& value : x) {
      if (!(ss >> value) || !std::isfinite(value)) {
        throw RecordingError(At(file, line_no) + ": expected 'name k11..k33 r11..r33 t1 t2 t3' (21 numbers)");
      }
    }
    std::string extra;
    if (ss >> extra) throw RecordingError(At(file, line_no) + ": unexpected text after t3: '" + extra + "'");
    v.K = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(x);
    v.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(x + 9);
    v.t = Eigen::Vector3d(x[18], x[19], x[20]);
    views.push_back(std::move(v));
  }
  if (declared < 0) throw RecordingError(file.string() + ": is empty");
  if (static_cast<long>(views.size()) != declared) {
    throw RecordingError(file.string() + ": declares " + std::to_string(declared) + " images on line 1 but lists " +
                         std::to_string(views.size()));
  }
  return views;
}

// The shared camera of all views; throws naming the first view whose K differs from the first
// view's, or whose K is not of the form [fx 0 cx; 0 fy cy; 0 0 1].
calib::Camera SharedIntrinsics(const std::vector<MiddleburyView>& views, const fs::path& file, int width, int height) {
  const Eigen::Matrix3d& K0 = views.front().K;
  for (const MiddleburyView& v : views) {
    const Eigen::Matrix3d& K = v.K;
    if (std::abs(K(2, 2) - 1.0) > 1e-9 || std::abs(K(1, 0)) > 1e-9 || std::abs(K(2, 0)) > 1e-9 ||
        std::abs(K(2, 1)) > 1e-9) {
      throw RecordingError(At(file, v.line_no) + ": K is not an upper-triangular camera matrix with k33 = 1");
    }
    if (std::abs(K(0, 1)) > 1e-9 * K(0, 0)) {
      throw RecordingError(At(file, v.line_no) + ": K has skew k12 = " + std::to_string(K(0, 1)) +
                           "; arview's camera model has none");
    }
    if ((K - K0).cwiseAbs().maxCoeff() > 1e-6 * K0(0, 0)) {
      throw RecordingError(At(file, v.line_no) + ": K of " + v.name + " differs from K of " + views.front().name +
                           " (line " + std::to_string(views.front().line_no) +
                           "); a recording has one camera, so varying intrinsics cannot be imported");
    }
  }
  calib::Camera camera = calib::Camera::Pinhole(width, height, K0(0, 0), K0(1, 1), K0(0, 2), K0(1, 2));
  try {
    camera.Validate(file.string());
  } catch (const calib::CameraError& e) {
    throw RecordingError(e.what());
  }
  return camera;
}

// ---------------------------------------------------------------- Strecha

struct StrechaCamera {
  Eigen::Matrix3d K;
  Eigen::Matrix3d R_wc;  // camera-to-world
  Eigen::Vector3d C;
  int width = 0, height = 0;
};

StrechaCamera ReadStrechaCamera(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw RecordingError(file.string() + ": missing (every image needs its .camera file)");
  std::istringstream in(ReadRecordingText(file));
  std::vector<std::vector<double>> rows;
  std::vector<int> line_of_row;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ss(line);
    std::vector<double> row;
    std::string tok;
    while (ss >> tok) {
      char* end = nullptr;
      const double v = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != '\0' || !std::isfinite(v)) {
        throw RecordingError(At(file, line_no) + ": '" + tok + "' is not a number");
      }
      row.push_back(v);
    }
    rows.push_back(std::move(row));
    line_of_row.push_back(line_no);
  }
  // K (3 rows of 3), distortion (3), R (3 rows of 3), C (3), size (2).
  const std::vector<size_t> expected = {3, 3, 3, 3, 3, 3, 3, 3, 2};
  const char* what[] = {"K row 1", "K row 2", "K row 3", "distortion (3 values)", "R row 1", "R row 2",
                        "R row 3", "camera centre C", "width height"};
  if (rows.size() < expected.size()) {
    throw RecordingError(file.string() + ": has " + std::to_string(rows.size()) + " non-empty lines, expected " +
                         std::to_string(expected.size()) + " (K, distortion, R, C, width height)");
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    if (rows[i].size() != expected[i]) {
      throw RecordingError(At(file, line_of_row[i]) + ": expected " + what[i] + ", got " +
                           std::to_string(rows[i].size()) + " numbers");
    }
  }
  StrechaCamera c;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      c.K(r, k) = rows[r][k];
      c.R_wc(r, k) = rows[4 + r][k];
    }
  }
  for (double d : rows[3]) {
    if (d != 0) {
      throw RecordingError(At(file, line_of_row[3]) +
                           ": non-zero distortion values are not supported (their model is not documented)");
    }
  }
  c.C = Eigen::Vector3d(rows[7][0], rows[7][1], rows[7][2]);
  c.width = static_cast<int>(rows[8][0]);
  c.height = static_cast<int>(rows[8][1]);
  if (c.width != rows[8][0] || c.height != rows[8][1] || c.width <= 0 || c.height <= 0) {
    throw RecordingError(At(file, line_of_row[8]) + ": width and height must be positive integers");
  }
  c.R_wc = NearestRotation(c.R_wc, 1e-4, At(file, line_of_row[4]));
  return c;
}

}  // namespace

ImportResult ImportMiddlebury(const fs::path& source_dir, const fs::path& out_dir, const ImportOptions& options) {
  RequireDirectory(source_dir, "Middlebury folder");
  const fs::path par = FindParFile(source_dir);
  std::vector<MiddleburyView> views = ReadParFile(par);
  std::sort(views.begin(), views.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (size_t i = 1; i < views.size(); ++i) {
    if (views[i].name == views[i - 1].name) {
      throw RecordingError(At(par, views[i].line_no) + ": image " + views[i].name + " is listed twice");
    }
  }
  std::vector<fs::path> images;
  for (const MiddleburyView& v : views) {
    const fs::path image = source_dir / v.name;
    if (!fs::is_regular_file(image)) {
      throw RecordingError(At(par, v.line_no) + ": image " + image.string() + " does not exist");
    }
    images.push_back(image);
  }
  const cv::Mat first = ReadSourceImage(images.front());
  calib::Camera camera = SharedIntrinsics(views, par, first.cols, first.rows);
  std::vector<std::string> notes;
  if (options.camera) {
    notes.push_back("--camera ignored: the Middlebury file gives the intrinsics");
  }
  PreparedOutput prepared(out_dir, options.overwrite);
  const std::vector<FrameEntry> frames = StoreStills(images, out_dir, camera, "the first image " + images[0].string());
  Trajectory gt;
  for (size_t i = 0; i < views.size(); ++i) {
    const Eigen::Matrix3d R = NearestRotation(views[i].R, 1e-4, At(par, views[i].line_no));
    gt.push_back({frames[i].timestamp, calib::Pose::FromRt(R, views[i].t)});
  }
  notes.push_back("intrinsics are shared by all " + std::to_string(views.size()) + " images of " +
                  par.filename().string());
  ImportResult result = Finish(out_dir, camera, frames, &gt, std::move(notes));
  prepared.Commit();
  return result;
}

ImportResult ImportStrecha(const fs::path& source_dir, const fs::path& out_dir, const ImportOptions& options) {
  RequireDirectory(source_dir, "Strecha folder");
  RequireDirectory(source_dir / "images", "Strecha images folder");
  RequireDirectory(source_dir / "gt_dense_cameras", "Strecha ground-truth camera folder");
  const std::vector<fs::path> images = ImagesInFolder(source_dir / "images");
  std::vector<StrechaCamera> cams;
  for (const fs::path& image : images) {
    cams.push_back(ReadStrechaCamera(source_dir / "gt_dense_cameras" / (image.filename().string() + ".camera")));
  }
  const fs::path first_cam = source_dir / "gt_dense_cameras" / (images[0].filename().string() + ".camera");
  const Eigen::Matrix3d& K0 = cams[0].K;
  for (size_t i = 0; i < cams.size(); ++i) {
    const fs::path cam_file = source_dir / "gt_dense_cameras" / (images[i].filename().string() + ".camera");
    const Eigen::Matrix3d& K = cams[i].K;
    if (std::abs(K(0, 1)) > 1e-9 * K(0, 0) || K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1) {
      throw RecordingError(cam_file.string() + ": K must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
    }
    if ((K - K0).cwiseAbs().maxCoeff() > 1e-6 * K0(0, 0) || cams[i].width != cams[0].width ||
        cams[i].height != cams[0].height) {
      throw RecordingError(cam_file.string() + ": intrinsics or image size differ from " + first_cam.string() +
                           "; a recording has one camera");
    }
  }
  calib::Camera camera = calib::Camera::Pinhole(cams[0].width, cams[0].height, K0(0, 0), K0(1, 1), K0(0, 2), K0(1, 2));
  try {
    camera.Validate(first_cam.string());
  } catch (const calib::CameraError& e) {
    throw RecordingError(e.what());
  }
  std::vector<std::string> notes;
  if (options.camera) notes.push_back("--camera ignored: the .camera files give the intrinsics");
  PreparedOutput prepared(out_dir, options.overwrite);
  const std::vector<FrameEntry> frames = StoreStills(images, out_dir, camera, first_cam.string());
  Trajectory gt;
  for (size_t i = 0; i < cams.size(); ++i) {
    gt.push_back({frames[i].timestamp, calib::Pose::FromCameraToWorld(Eigen::Quaterniond(cams[i].R_wc), cams[i].C)});
  }
  ImportResult result = Finish(out_dir, camera, frames, &gt, std::move(notes));
  prepared.Commit();
  return result;
}

namespace {

// The camera of an import without a calibration (ImportOptions::horizontal_fov_deg), with a
// note saying what it is.
calib::Camera EstimatedCamera(int width, int height, const ImportOptions& options, const fs::path* exif_image,
                              std::vector<std::string>* notes) {
  double focal = 0;
  std::string source;
  std::string exif_ignored;
  std::optional<FocalFromMetadata> from_exif;
  if (options.horizontal_fov_deg) {
    try {
      focal = calib::FocalFromHorizontalFov(width, *options.horizontal_fov_deg, "--fov");
    } catch (const calib::CameraError& e) {
      throw RecordingError(e.what());
    }
    std::ostringstream s;
    s << "--fov " << *options.horizontal_fov_deg << " degrees across the width";
    source = s.str();
  } else if (exif_image && (from_exif = ReadFocalFromExif(*exif_image, width, height, &exif_ignored))) {
    focal = from_exif->focal_px;
    source = from_exif->description;
  } else {
    focal = calib::GuessedFocal(width, height);
    source = "a guess: focal length 0.6 x the diagonal, a phone's or a webcam's (no --camera, no --fov, no focal length in the file)";
  }
  if (!exif_ignored.empty()) notes->push_back(exif_ignored);
  calib::Camera camera = calib::EstimatedCamera(width, height, focal, source);
  std::ostringstream s;
  s << "no --camera: the camera is not calibrated; focal length " << std::lround(focal) << " px from " << source
    << ". `arview map` refines it (a calibration, `arview calibrate`, is more accurate)";
  notes->push_back(s.str());
  return camera;
}

// The camera of an import from images or a video whose first frame is cols x rows: --camera's
// when given (a --fov beside it is noted as ignored), else the estimate above.
calib::Camera ChooseImportCamera(int cols, int rows, const ImportOptions& options, const fs::path* exif_file,
                                 std::vector<std::string>* notes) {
  if (!options.camera) return EstimatedCamera(cols, rows, options, exif_file, notes);
  if (options.horizontal_fov_deg) notes->push_back("--fov ignored: --camera gives the intrinsics");
  return *options.camera;
}

}  // namespace

ImportResult ImportTum(const fs::path& source_dir, const fs::path& out_dir, const ImportOptions& options) {
  RequireDirectory(source_dir, "TUM RGB-D folder");
  const fs::path rgb_txt = source_dir / "rgb.txt";
  std::error_code ec;
  // A FIFO or a device so named is refused by ReadFrameList, naming what it is.
  if (!fs::exists(rgb_txt, ec)) throw RecordingError(rgb_txt.string() + ": missing (a TUM RGB-D folder has rgb.txt)");
  const std::vector<FrameEntry> list = ReadFrameList(rgb_txt);
  calib::Camera camera;
  std::string camera_source = "--camera";
  if (options.camera) {
    camera = *options.camera;
  } else if (fs::exists(source_dir / "camera.yaml", ec)) {
    camera_source = (source_dir / "camera.yaml").string();
    try {
      camera = calib::LoadCamera(source_dir / "camera.yaml");
    } catch (const calib::CameraError& e) {
      throw RecordingError(e.what());
    }
  } else {
    throw RecordingError("import tum: " + source_dir.string() +
                         " holds no camera.yaml and TUM folders carry no intrinsics; give --camera camera.yaml");
  }
  const fs::path gt_file = source_dir / "groundtruth.txt";
  std::optional<Trajectory> gt;
  if (fs::exists(gt_file, ec)) gt = ReadTum(gt_file);
  PreparedOutput prepared(out_dir, options.overwrite);
  std::vector<FrameEntry> frames;
  for (size_t i = 0; i < list.size(); ++i) {
    const fs::path image_file = source_dir / list[i].path;
    if (!fs::is_regular_file(image_file, ec)) {
      throw RecordingError(image_file.string() + ": listed in " + (source_dir / "rgb.txt").string() + " but missing");
    }
    const cv::Mat image = ReadSourceImage(image_file);
    CheckSize(image, image_file, camera, camera_source);
    StoreFrame(image_file, image, out_dir, i, &frames, list[i].timestamp);
  }
  std::vector<std::string> notes;
  if (!gt) notes.push_back(gt_file.string() + " absent: the recording has no ground truth");
  ImportResult result = Finish(out_dir, camera, frames, gt ? &*gt : nullptr, std::move(notes));
  prepared.Commit();
  return result;
}

ImportResult ImportImages(const fs::path& source_dir, const fs::path& out_dir, const ImportOptions& options) {
  RequireDirectory(source_dir, "image folder");
  const std::vector<fs::path> images = ImagesInFolder(source_dir);
  std::vector<std::string> notes;
  const bool estimated = !options.camera;
  const cv::Size first = estimated ? ReadSourceImage(images.front()).size() : cv::Size();
  const calib::Camera camera = ChooseImportCamera(first.width, first.height, options, &images.front(), &notes);
  const std::string camera_source = estimated ? "the first image " + images.front().string() : "--camera";
  PreparedOutput prepared(out_dir, options.overwrite);
  const std::vector<FrameEntry> frames = StoreStills(images, out_dir, camera, camera_source);
  ImportResult result = Finish(out_dir, camera, frames, nullptr, std::move(notes));
  prepared.Commit();
  return result;
}

ImportResult ImportVideo(const fs::path& video_file, const fs::path& out_dir, const ImportOptions& options) {
  try {
    RequireRegularFile(video_file);  // "does not exist", or what it is instead (a FIFO, a device)
  } catch (const InputError& e) {
    throw RecordingError(std::string(e.what()) + " (the video to import)");
  }
  cv::VideoCapture cap;
  if (!cap.open(video_file.string(), cv::CAP_FFMPEG)) {
    throw RecordingError(video_file.string() + ": cannot be opened as a video (OpenCV FFmpeg backend)");
  }
  const double fps = cap.get(cv::CAP_PROP_FPS);
  std::vector<double> stamps;
  std::vector<std::string> notes;
  calib::Camera camera;
  cv::Mat image;
  while (cap.read(image)) {
    if (stamps.empty()) {
      camera = ChooseImportCamera(image.cols, image.rows, options, nullptr, &notes);
      CheckSize(image, video_file, camera, "--camera");
    }
    stamps.push_back(cap.get(cv::CAP_PROP_POS_MSEC) / 1000.0);
  }
  if (stamps.empty()) throw RecordingError(video_file.string() + ": holds no decodable frames");
  // Container timestamps are used when they increase strictly; otherwise index / fps.
  bool increasing = true;
  for (size_t i = 1; i < stamps.size(); ++i) increasing = increasing && stamps[i] > stamps[i - 1];
  if (!increasing) {
    const double rate = (std::isfinite(fps) && fps > 0) ? fps : 30.0;
    if (!(std::isfinite(fps) && fps > 0)) notes.push_back("the video declares no frame rate; assumed 30 fps");
    for (size_t i = 0; i < stamps.size(); ++i) stamps[i] = static_cast<double>(i) / rate;
    char text[160];
    std::snprintf(text, sizeof(text),
                  "the decoder's frame times do not increase throughout (OpenCV reports none for the last "
                  "frames of many files); timestamps = frame index / %.6g fps",
                  rate);
    notes.push_back(text);
  }
  PreparedOutput prepared(out_dir, options.overwrite);
  const std::string rel = "frames/" + video_file.filename().string();
  std::error_code ec;
  fs::copy_file(video_file, out_dir / rel, fs::copy_options::overwrite_existing, ec);
  if (ec) throw RecordingError((out_dir / rel).string() + ": cannot copy the video (" + ec.message() + ")");
  std::vector<FrameEntry> frames;
  for (double t : stamps) frames.push_back({t, rel});
  ImportResult result = Finish(out_dir, camera, frames, nullptr, std::move(notes));
  prepared.Commit();
  return result;
}

const std::vector<std::string>& ImporterKinds() {
  static const std::vector<std::string> kinds = {"middlebury", "strecha", "tum", "images", "video"};
  return kinds;
}

ImportResult Import(const std::string& kind, const fs::path& source, const fs::path& out_dir,
                    const ImportOptions& options) {
  if (kind == "middlebury") return ImportMiddlebury(source, out_dir, options);
  if (kind == "strecha") return ImportStrecha(source, out_dir, options);
  if (kind == "tum") return ImportTum(source, out_dir, options);
  if (kind == "images") return ImportImages(source, out_dir, options);
  if (kind == "video") return ImportVideo(source, out_dir, options);
  throw RecordingError("import: unknown kind '" + kind +
                       "' (expected middlebury, strecha, tum, images or video)");
}

}  // namespace arview::recordings
