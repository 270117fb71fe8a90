#pragma once
// Shared by the COLMAP targets (fuzz_colmap_model, fuzz_colmap_database): a small valid model in
// COLMAP's binary format and a database as COLMAP lays it out (the two tables arview reads).

#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace arview::fuzz {

inline void Exec(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "?";
    sqlite3_free(error);
    throw std::runtime_error("fuzz database: " + message);
  }
}

// The tables of COLMAP's database.db that mapping::ReadColmapMap reads.
inline constexpr const char* kColmapDatabaseSchema =
    "CREATE TABLE images(image_id INTEGER PRIMARY KEY, name TEXT);"
    "CREATE TABLE descriptors(image_id INTEGER PRIMARY KEY, rows INTEGER, cols INTEGER, data BLOB);";

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

struct ColmapModelFiles {
  std::string cameras, images, points;
};

// A valid model: one PINHOLE camera, two images (ids 1 and 2, named frames/00000<id>.png), three
// points each seen by both images (2D point indices 0-2 of each image).
inline ColmapModelFiles SmallColmapModel() {
  ColmapModelFiles m;
  Put<std::uint64_t>(m.cameras, 1);
  Put<std::uint32_t>(m.cameras, 1);  // camera id
  Put<std::int32_t>(m.cameras, 1);   // PINHOLE
  Put<std::uint64_t>(m.cameras, 640);
  Put<std::uint64_t>(m.cameras, 480);
  for (double v : {500.0, 500.0, 319.5, 239.5}) Put(m.cameras, v);
  Put<std::uint64_t>(m.images, 2);
  for (std::uint32_t id = 1; id <= 2; ++id) {
    Put(m.images, id);
    for (double v : {1.0, 0.0, 0.0, 0.0, 0.1 * id, 0.0, 0.0}) Put(m.images, v);
    Put<std::uint32_t>(m.images, 1);
    m.images += "frames/00000" + std::to_string(id) + ".png";
    m.images += '\0';
    Put<std::uint64_t>(m.images, 3);
    for (std::uint64_t p = 1; p <= 3; ++p) {
      Put(m.images, 100.0 * p);
      Put(m.images, 80.0 * p);
      Put<std::int64_t>(m.images, static_cast<std::int64_t>(p));
    }
  }
  Put<std::uint64_t>(m.points, 3);
  for (std::uint64_t p = 1; p <= 3; ++p) {
    Put(m.points, p);
    for (double v : {0.1 * p, -0.2, 4.0}) Put(m.points, v);
    m.points += "\x10\x20\x30";
    Put(m.points, 0.5);
    Put<std::uint64_t>(m.points, 2);
    for (std::uint32_t id = 1; id <= 2; ++id) {
      Put(m.points, id);
      Put<std::uint32_t>(m.points, static_cast<std::uint32_t>(p - 1));
    }
  }
  return m;
}

}  // namespace arview::fuzz
