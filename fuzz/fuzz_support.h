#pragma once
// Shared by the libFuzzer targets: a per-process scratch folder and writing an input to a file
// in it (most of our parsers take a path, as the program gives them one).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace arview::fuzz {

// A folder of its own per fuzzing process (libFuzzer may run several), removed at exit.
inline const std::filesystem::path& ScratchFolder() {
  struct Folder {
    std::filesystem::path path;
    Folder() {
      path = std::filesystem::temp_directory_path() / ("arview-fuzz-" + std::to_string(::getpid()));
      std::filesystem::create_directories(path);
    }
    ~Folder() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Folder folder;
  return folder.path;
}

inline void WriteBytes(const std::filesystem::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Writes the input to `name` inside the scratch folder and returns its path.
inline std::filesystem::path WriteInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = ScratchFolder() / name;
  WriteBytes(file, std::string_view(reinterpret_cast<const char*>(data), size));
  return file;
}

// Splits an input into parts at `separator` (used where one input stands for several files).
inline std::string_view NextPart(std::string_view& rest, std::string_view separator) {
  const size_t at = rest.find(separator);
  std::string_view part = rest.substr(0, at);
  rest = at == std::string_view::npos ? std::string_view{} : rest.substr(at + separator.size());
  return part;
}

}  // namespace arview::fuzz

namespace arview::fuzz {

// scripts/fuzz.sh sets ARVIEW_FUZZ_WRITE_SEED to a folder before a run: targets whose inputs
// our own writers make (map files, camera files, COLMAP models) write a valid one there from
// LLVMFuzzerInitialize, so that every run starts from a real file of the current format.
inline std::filesystem::path SeedFolderToWrite() {
  const char* folder = std::getenv("ARVIEW_FUZZ_WRITE_SEED");
  if (!folder || !*folder) return {};
  std::filesystem::create_directories(folder);
  return folder;
}

}  // namespace arview::fuzz
