// Issue 41: every exception a library throws past a reader's own checks (std::bad_alloc,
// std::length_error, std::filesystem::filesystem_error, cv::Exception, YAML::Exception,
// nlohmann-json's) is caught where the input is known and leaves as the reader's arview::Error,
// its message starting with the input (base/library_errors.h NamingInput). Each reader is walked
// with inputs that make each library throw: names too long for the file system, texts OpenCV,
// yaml-cpp and nlohmann-json refuse, and files too large for the memory a child process is left.
// A binary of its own (library_exceptions_tests): under ASan it has an operator new that throws
// std::bad_alloc, as the last case needs (throwing_new.cpp).

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <typeinfo>
#include <vector>

#include "anim/character.h"
#include "anim_authoring/import.h"
#include "anim_authoring/scene.h"
#include "base/image_file.h"
#include "calib/camera.h"
#include "fuzz/colmap_fixture.h"
#include "map/map_file.h"
#include "mapping/colmap_model.h"
#include "mapping/map_check.h"
#include "recordings/recording.h"
#include "recordings/trajectory.h"
#include "room/room_light.h"

namespace arview {
namespace {

namespace fs = std::filesystem;

// What a reader threw: "<its error type's tag>: <what()>" when it is the reader's own error type
// E, "OTHER <type>: <what()>" for anything else, "" when nothing was thrown.
template <class E>
std::string Outcome(const std::function<void()>& read) {
  try {
    read();
  } catch (const E& e) {
    return std::string("OWN: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("OTHER ") + typeid(e).name() + ": " + e.what();
  }
  return "";
}

struct Reader {
  std::string name;
  fs::path input;                      // what the message must start with
  std::function<std::string()> read;   // Outcome<its error type>(...)
};

class LibraryExceptions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arview_library_exceptions_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  // Every reader, each on `path(extension)`.
  std::vector<Reader> Readers(const std::function<fs::path(const std::string&)>& path) {
    std::vector<Reader> readers;
    auto add = [&](const std::string& name, const fs::path& input, std::function<std::string()> read) {
      readers.push_back({name, input, std::move(read)});
    };
    const fs::path camera = path(".yaml"), light = path(".light.yml"), tum = path(".txt"), map_file = path(".arvmap"),
                   scene = path(".scene.yaml"), glb = path(".glb"), png = path(".png"), check = path(".json"),
                   folder = path("");
    add("LoadCamera", camera, [=] { return Outcome<calib::CameraError>([&] { calib::LoadCamera(camera); }); });
    add("LoadRoomLight", light, [=] { return Outcome<room::LightError>([&] { room::LoadRoomLight(light); }); });
    add("ReadTum", tum, [=] { return Outcome<recordings::RecordingError>([&] { recordings::ReadTum(tum); }); });
    add("LoadRecording", folder,
        [=] { return Outcome<recordings::RecordingError>([&] { recordings::LoadRecording(folder); }); });
    add("LoadMap", map_file, [=] { return Outcome<map::MapError>([&] { map::LoadMap(map_file); }); });
    add("ReadColmapMap", folder,
        [=] { return Outcome<map::MapError>([&] { mapping::ReadColmapMap(folder, folder / "database.db"); }); });
    add("ReadMapCheck", check, [=] { return Outcome<map::MapError>([&] { mapping::ReadMapCheck(check); }); });
    add("LoadScene", scene, [=] { return Outcome<anim::Error>([&] { authoring::LoadScene(scene); }); });
    add("LoadCharacter", glb, [=] { return Outcome<anim::Error>([&] { authoring::LoadCharacter(glb); }); });
    add("ReadImageFile", png, [=] { return Outcome<Error>([&] { ReadImageFile(png, 1); }); });  // 1: cv::IMREAD_COLOR
    return readers;
  }

  fs::path dir_;
};

void ExpectOwnErrorNaming(const std::string& outcome, const fs::path& input, const std::string& reader) {
  EXPECT_EQ(outcome.rfind("OWN: " + input.string(), 0), 0u) << reader << ": " << outcome;
  for (const char* raw : {"filesystem error", "basic_string", "std::bad_alloc"}) {
    EXPECT_EQ(outcome.find(raw), std::string::npos) << reader << ": " << outcome;
  }
}

// A name longer than the file system allows (ENAMETOOLONG): std::filesystem's queries throw
// filesystem_error (LoadRoomLight's did, and reached the user as "filesystem error: status: ...").
TEST_F(LibraryExceptions, ANameTooLongIsTheReadersErrorNamingIt) {
  const std::string long_name(300, 'x');
  for (const Reader& r : Readers([&](const std::string& extension) { return dir_ / (long_name + extension); })) {
    ExpectOwnErrorNaming(r.read(), r.input, r.name);
  }
}

// Texts each library refuses by throwing: OpenCV's FileStorage (cv::Exception), yaml-cpp
// (YAML::Exception), nlohmann-json (parse_error, type_error, out_of_range); and a matrix without
// its dt key, which made OpenCV throw std::length_error.
TEST_F(LibraryExceptions, TextsALibraryRefusesAreTheReadersErrorNamingTheFile) {
  struct Case {
    std::string name;
    fs::path file;
    std::function<std::string()> read;
  };
  const std::string camera_head = "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n";
  const fs::path camera_syntax = Write("syntax.yaml", camera_head + "camera_matrix: { rows: 3\n");
  const fs::path camera_no_dt = Write("no_dt.yaml", camera_head + "camera_matrix: !!opencv-matrix\n   rows: 3\n"
                                                                  "   cols: 3\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n");
  const fs::path light_syntax = Write("syntax.light.yml", "%YAML:1.0\n---\nformat: \"arview room light 1\n");
  const fs::path scene_syntax = Write("syntax.scene.yaml", "characters: [ {asset: a.glb\n");
  const fs::path gltf_syntax = Write("syntax.gltf", "{\"asset\": {\"version\": \"2.0\"}");
  const fs::path gltf_type = Write("type.gltf", "{\"asset\": {\"version\": 2}}");
  const fs::path check_syntax = Write("syntax.json", "{\"keyframes\": ");
  const fs::path check_type = Write("type.json", "{\"keyframes\": \"many\"}");
  const fs::path check_missing = Write("missing.json", "{}");
  const std::vector<Case> cases = {
      {"cv::Exception, camera", camera_syntax,
       [&] { return Outcome<calib::CameraError>([&] { calib::LoadCamera(camera_syntax); }); }},
      {"std::length_error, camera", camera_no_dt,
       [&] { return Outcome<calib::CameraError>([&] { calib::LoadCamera(camera_no_dt); }); }},
      {"cv::Exception, room light", light_syntax,
       [&] { return Outcome<room::LightError>([&] { room::LoadRoomLight(light_syntax); }); }},
      {"YAML::Exception, scene", scene_syntax,
       [&] { return Outcome<anim::Error>([&] { authoring::LoadScene(scene_syntax); }); }},
      {"json parse_error, glTF", gltf_syntax,
       [&] { return Outcome<anim::Error>([&] { authoring::LoadCharacter(gltf_syntax); }); }},
      {"json type_error, glTF", gltf_type,
       [&] { return Outcome<anim::Error>([&] { authoring::LoadCharacter(gltf_type); }); }},
      {"json parse_error, check.json", check_syntax,
       [&] { return Outcome<map::MapError>([&] { mapping::ReadMapCheck(check_syntax); }); }},
      {"json type_error, check.json", check_type,
       [&] { return Outcome<map::MapError>([&] { mapping::ReadMapCheck(check_type); }); }},
      {"json out_of_range, check.json", check_missing,
       [&] { return Outcome<map::MapError>([&] { mapping::ReadMapCheck(check_missing); }); }},
  };
  for (const Case& c : cases) ExpectOwnErrorNaming(c.read(), c.file, c.name);
}

// `read` in a child process left `headroom` bytes of address space beyond what it uses now; what
// it returned, or "CRASHED" when the child did not end by itself.
std::string WithLittleMemory(std::size_t headroom, const std::function<std::string()>& read) {
  int fds[2];
  if (::pipe(fds) != 0) return "no pipe";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    long pages = 0;
    if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
      std::fclose(statm);
    }
    const rlim_t limit = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE)) + headroom;
    const rlimit cap{limit, limit};
    std::string result = ::setrlimit(RLIMIT_AS, &cap) == 0 ? read() : "setrlimit failed";
    if (::write(fds[1], result.data(), result.size()) < 0) _exit(2);
    _exit(0);
  }
  ::close(fds[1]);
  std::string result;
  char buffer[4096];
  ssize_t n;
  while ((n = ::read(fds[0], buffer, sizeof buffer)) > 0) result.append(buffer, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? result : "CRASHED: " + result;
}

// Files within every reader's size limit but larger than the memory left: the reader's buffer
// cannot be allocated (std::bad_alloc), and the error names the file.
TEST_F(LibraryExceptions, AFileLargerThanTheMemoryLeftIsTheReadersErrorNamingIt) {
  constexpr std::uintmax_t kFileBytes = 48u << 20;  // under the 64 MiB of text files, sparse on disk
  const fs::path folder = dir_ / "big";
  fs::create_directories(folder);
  auto big = [&](const fs::path& file) {
    std::ofstream(file, std::ios::binary).close();
    fs::resize_file(file, kFileBytes);
    return file;
  };
  // A recording whose frames.txt is large; a COLMAP model whose cameras.bin is.
  const fuzz::ColmapModelFiles model = fuzz::SmallColmapModel();
  Write("big/camera.yaml", "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
                           "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n");
  big(folder / "frames.txt");
  big(folder / "cameras.bin");
  std::ofstream(folder / "images.bin", std::ios::binary) << model.images;
  std::ofstream(folder / "points3D.bin", std::ios::binary) << model.points;
  int walked = 0;
  for (const Reader& r : Readers([&](const std::string& extension) {
         return extension.empty() ? folder : big(dir_ / ("big" + extension));
       })) {
    if (r.name == "LoadCamera" || r.name == "LoadScene" || r.name == "ReadMapCheck") continue;  // limits of 1-4 MiB
    ++walked;
    const std::string outcome = WithLittleMemory(16u << 20, r.read);
    ExpectOwnErrorNaming(outcome, r.input, r.name);
    EXPECT_NE(outcome.find("not enough memory to read it"), std::string::npos) << r.name << ": " << outcome;
  }
  EXPECT_EQ(walked, 7);
}

}  // namespace
}  // namespace arview
