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

#include "fuzz/fuzz_support.h"
#include "mapping/colmap_model.h"

namespace {

void Exec(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "?";
    sqlite3_free(error);
    throw std::runtime_error("fuzz database: " + message);
  }
}

std::filesystem::path MakeDatabase(const std::filesystem::path& file) {
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) throw std::runtime_error("fuzz database: cannot open");
  Exec(db, "CREATE TABLE images(image_id INTEGER PRIMARY KEY, name TEXT);"
           "CREATE TABLE descriptors(image_id INTEGER PRIMARY KEY, rows INTEGER, cols INTEGER, data BLOB);");
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

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

void PutSized(std::string& out, const std::string& part) {
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(part.size()));
  out += part;
}

// A valid model in COLMAP's binary format: one PINHOLE camera, two images, three points each
// seen by both images.
std::string SmallModel() {
  std::string cameras, images, points;
  Put<std::uint64_t>(cameras, 1);
  Put<std::uint32_t>(cameras, 1);  // camera id
  Put<std::int32_t>(cameras, 1);   // PINHOLE
  Put<std::uint64_t>(cameras, 640);
  Put<std::uint64_t>(cameras, 480);
  for (double v : {500.0, 500.0, 319.5, 239.5}) Put(cameras, v);
  Put<std::uint64_t>(images, 2);
  for (std::uint32_t id = 1; id <= 2; ++id) {
    Put(images, id);
    for (double v : {1.0, 0.0, 0.0, 0.0, 0.1 * id, 0.0, 0.0}) Put(images, v);
    Put<std::uint32_t>(images, 1);
    images += "frames/00000" + std::to_string(id) + ".png";
    images += '\0';
    Put<std::uint64_t>(images, 3);
    for (std::uint64_t p = 1; p <= 3; ++p) {
      Put(images, 100.0 * p);
      Put(images, 80.0 * p);
      Put<std::int64_t>(images, static_cast<std::int64_t>(p));
    }
  }
  Put<std::uint64_t>(points, 3);
  for (std::uint64_t p = 1; p <= 3; ++p) {
    Put(points, p);
    for (double v : {0.1 * p, -0.2, 4.0}) Put(points, v);
    points += "\x10\x20\x30";
    Put(points, 0.5);
    Put<std::uint64_t>(points, 2);
    for (std::uint32_t id = 1; id <= 2; ++id) {
      Put(points, id);
      Put<std::uint32_t>(points, static_cast<std::uint32_t>(p - 1));
    }
  }
  std::string input;
  PutSized(input, cameras);
  PutSized(input, images);
  return input + points;
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
