// COLMAP's database.db, the second input of mapping::ReadColmapMap (image names and SIFT
// descriptors), against a fixed valid model (fuzz/colmap_fixture.h: images 1 and 2, three
// observations each). The first byte chooses how the rest is read:
// - odd: the rest is the database file itself (a damaged or hostile SQLite file);
// - even: the tables' contents, one record per image id 1-3 (3 is not in the model):
//   flags (bit 0: an images row, bit 1: a descriptors row), the name (1-byte length, bytes),
//   rows and cols (each a type byte and 8 bytes), data (a type byte, 2-byte length, bytes).
//   SQLite stores any type in any column: the type byte picks integer, real, text, NULL or blob,
//   so that a name that is a blob, a row count that is text or descriptors that are NULL reach
//   the reader as COLMAP's schema would never write them.
#include <sqlite3.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>

#include "fuzz/colmap_fixture.h"
#include "fuzz/fuzz_support.h"
#include "mapping/colmap_model.h"

namespace {

using arview::fuzz::Exec;
using arview::fuzz::Put;

struct Statement {
  sqlite3_stmt* st = nullptr;
  ~Statement() { sqlite3_finalize(st); }
};

struct Database {
  sqlite3* db = nullptr;
  ~Database() { sqlite3_close(db); }
};

// Bytes taken from the front of the input; zeros once it has run out.
class Input {
 public:
  explicit Input(std::string_view bytes) : rest_(bytes) {}
  std::uint8_t Byte() { return rest_.empty() ? 0 : static_cast<std::uint8_t>(Take(1)[0]); }
  std::string_view Take(size_t n) {
    const std::string_view part = rest_.substr(0, std::min(n, rest_.size()));
    rest_.remove_prefix(part.size());
    return part;
  }
  std::int64_t Int64() {
    std::int64_t v = 0;
    const std::string_view b = Take(8);
    std::memcpy(&v, b.data(), b.size());
    return v;
  }

 private:
  std::string_view rest_;
};

// Binds parameter `index` as the value the type byte asks for.
void BindNumber(sqlite3_stmt* st, int index, std::uint8_t type, std::int64_t value) {
  switch (type % 5) {
    case 0: sqlite3_bind_int64(st, index, value); break;
    case 1: {
      double d = 0;
      std::memcpy(&d, &value, sizeof d);
      sqlite3_bind_double(st, index, d);
      break;
    }
    case 2: sqlite3_bind_text(st, index, std::to_string(value).c_str(), -1, SQLITE_TRANSIENT); break;
    case 3: sqlite3_bind_null(st, index); break;
    default: sqlite3_bind_blob(st, index, &value, sizeof value, SQLITE_TRANSIENT); break;
  }
}

void BindBytes(sqlite3_stmt* st, int index, std::uint8_t type, std::string_view bytes) {
  switch (type % 4) {
    case 0: sqlite3_bind_blob(st, index, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT); break;
    case 1: sqlite3_bind_text(st, index, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT); break;
    case 2: sqlite3_bind_null(st, index); break;
    default: sqlite3_bind_zeroblob(st, index, static_cast<int>(bytes.size())); break;
  }
}

void Insert(sqlite3* db, const char* sql, const std::function<void(sqlite3_stmt*)>& bind) {
  Statement s;
  if (sqlite3_prepare_v2(db, sql, -1, &s.st, nullptr) != SQLITE_OK) throw std::runtime_error("fuzz database: prepare");
  bind(s.st);
  sqlite3_step(s.st);  // a constraint the input breaks (a duplicate id) just leaves the row out
}

// The tables' contents from the input (the even mode above).
void FillDatabase(const std::filesystem::path& file, Input& in) {
  Database d;
  if (sqlite3_open(file.c_str(), &d.db) != SQLITE_OK) throw std::runtime_error("fuzz database: cannot open");
  Exec(d.db, "PRAGMA page_size=512; PRAGMA journal_mode=OFF;");
  Exec(d.db, arview::fuzz::kColmapDatabaseSchema);
  for (std::int64_t id = 1; id <= 3; ++id) {
    const std::uint8_t flags = in.Byte();
    const std::string_view name = in.Take(in.Byte());
    const std::uint8_t rows_type = in.Byte();
    const std::int64_t rows = in.Int64();
    const std::uint8_t cols_type = in.Byte();
    const std::int64_t cols = in.Int64();
    const std::uint8_t data_type = in.Byte();
    const size_t data_length = in.Byte() | (static_cast<size_t>(in.Byte()) << 8);
    const std::string_view data = in.Take(data_length);
    if (flags & 1) {
      Insert(d.db, "INSERT INTO images VALUES(?, ?)", [&](sqlite3_stmt* st) {
        sqlite3_bind_int64(st, 1, id);
        BindBytes(st, 2, flags >> 2, name);
      });
    }
    if (flags & 2) {
      Insert(d.db, "INSERT INTO descriptors VALUES(?, ?, ?, ?)", [&](sqlite3_stmt* st) {
        sqlite3_bind_int64(st, 1, id);
        BindNumber(st, 2, rows_type, rows);
        BindNumber(st, 3, cols_type, cols);
        BindBytes(st, 4, data_type, data);
      });
    }
  }
}

// A valid input of the even mode: both images named as in the model, three descriptors each.
std::string ValidTablesInput() {
  std::string input(1, '\0');
  for (int id = 1; id <= 2; ++id) {
    input += '\x03';
    const std::string name = "frames/00000" + std::to_string(id) + ".png";
    input += static_cast<char>(name.size());
    input += name;
    input += '\0';
    Put<std::int64_t>(input, 3);
    input += '\0';
    Put<std::int64_t>(input, 128);
    input += '\0';
    Put<std::uint16_t>(input, 3 * 128);
    for (int i = 0; i < 3 * 128; ++i) input += static_cast<char>((i * 37 + id) & 0xff);
  }
  return input;
}

const std::filesystem::path& Sparse() {
  static const std::filesystem::path folder = [] {
    const auto f = arview::fuzz::ScratchFolder() / "sparse";
    std::filesystem::create_directories(f);
    const arview::fuzz::ColmapModelFiles m = arview::fuzz::SmallColmapModel();
    arview::fuzz::WriteBytes(f / "cameras.bin", m.cameras);
    arview::fuzz::WriteBytes(f / "images.bin", m.images);
    arview::fuzz::WriteBytes(f / "points3D.bin", m.points);
    return f;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const auto seeds = arview::fuzz::SeedFolderToWrite();
  if (seeds.empty()) return 0;
  const std::string tables = ValidTablesInput();
  arview::fuzz::WriteBytes(seeds / "valid_tables", tables);
  // The same tables as a database file: the odd mode's seed.
  const auto file = arview::fuzz::ScratchFolder() / "seed.db";
  std::filesystem::remove(file);
  Input in(std::string_view(tables).substr(1));
  FillDatabase(file, in);
  std::ifstream db_file(file, std::ios::binary);
  const std::string db_bytes((std::istreambuf_iterator<char>(db_file)), std::istreambuf_iterator<char>());
  arview::fuzz::WriteBytes(seeds / "valid_database", "\x01" + db_bytes);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path database = arview::fuzz::ScratchFolder() / "database.db";
  std::error_code ec;
  std::filesystem::remove(database, ec);
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const bool raw_file = !bytes.empty() && (bytes[0] & 1);
  if (!bytes.empty()) bytes.remove_prefix(1);
  if (raw_file) {
    arview::fuzz::WriteBytes(database, bytes);
  } else {
    Input in(bytes);
    FillDatabase(database, in);
  }
  try {
    (void)arview::mapping::ReadColmapMap(Sparse(), database);
  } catch (const std::exception&) {
  }
  return 0;
}
