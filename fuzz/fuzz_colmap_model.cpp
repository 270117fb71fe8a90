// COLMAP's binary model (cameras.bin, images.bin, points3D.bin) through
// mapping::ReadColmapMap. The input holds the three files: a 4-byte little-endian length and
// cameras.bin, a 4-byte length and images.bin, then points3D.bin to the end. The database is
// fixed (made once): image ids 1-4 with names and 64 descriptors each, as COLMAP writes it.
#include <sqlite3.h>

#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>

#include "fuzz/colmap_fixture.h"
#include "fuzz/fuzz_support.h"
#include "mapping/colmap_model.h"

namespace {

using arview::fuzz::Exec;
using arview::fuzz::Put;

std::filesystem::path MakeDatabase(const std::filesystem::path& file) {
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) throw std::runtime_error("fuzz database: cannot open");
  Exec(db, arview::fuzz::kColmapDatabaseSchema);
  for (int id = 1; id <= 4; ++id) {
    Exec(db, "INSERT INTO images VALUES(" + std::to_string(id) + ", 'frames/00000" + std::to_string(id) + ".png');");
    Exec(db, "INSERT INTO descriptors VALUES(" + std::to_string(id) + ", 64, 128, randomblob(8192));");
  }
  sqlite3_close(db);
  return file;
}

// Takes a 4-byte length and that many bytes (fewer when the input ends first).
std::string_view TakeSized(std::string_view& rest) {
  if (rest.size() < 4) {
    rest = {};
    return {};
  }
  std::uint32_t length = 0;
  std::memcpy(&length, rest.data(), 4);
  rest.remove_prefix(4);
  const std::string_view part = rest.substr(0, length);
  rest.remove_prefix(part.size());
  return part;
}

void PutSized(std::string& out, const std::string& part) {
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(part.size()));
  out += part;
}

// The small valid model as one input.
std::string SmallModel() {
  const arview::fuzz::ColmapModelFiles m = arview::fuzz::SmallColmapModel();
  std::string input;
  PutSized(input, m.cameras);
  PutSized(input, m.images);
  return input + m.points;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (!seeds.empty()) arview::fuzz::WriteBytes(seeds / "small_model", SmallModel());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path database = MakeDatabase(arview::fuzz::ScratchFolder() / "database.db");
  static const std::filesystem::path sparse = [] {
    const auto folder = arview::fuzz::ScratchFolder() / "sparse";
    std::filesystem::create_directories(folder);
    return folder;
  }();
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  arview::fuzz::WriteBytes(sparse / "cameras.bin", TakeSized(rest));
  arview::fuzz::WriteBytes(sparse / "images.bin", TakeSized(rest));
  arview::fuzz::WriteBytes(sparse / "points3D.bin", rest);
  try {
    (void)arview::mapping::CountRegisteredImages(sparse);
    (void)arview::mapping::ReadColmapMap(sparse, database);
  } catch (const std::exception&) {
  }
  return 0;
}
