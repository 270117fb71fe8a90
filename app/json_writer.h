#pragma once
// A small JSON writer for stats files: nested objects and arrays, escaped strings, numbers
// written so that they read back exactly (non-finite numbers become null, as JSON has none).

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace arview::app {

class JsonWriter {
 public:
  JsonWriter& BeginObject(const std::string& key = "") { Open(key, '{'); return *this; }
  JsonWriter& EndObject() { Close('}'); return *this; }
  JsonWriter& BeginArray(const std::string& key = "") { Open(key, '['); return *this; }
  JsonWriter& EndArray() { Close(']'); return *this; }

  JsonWriter& Value(const std::string& key, double v) { Key(key); Number(v); return *this; }
  JsonWriter& Value(const std::string& key, long long v) { Key(key); out_ += std::to_string(v); return *this; }
  JsonWriter& Value(const std::string& key, int v) { return Value(key, static_cast<long long>(v)); }
  JsonWriter& Value(const std::string& key, size_t v) { return Value(key, static_cast<long long>(v)); }
  JsonWriter& Value(const std::string& key, bool v) { Key(key); out_ += v ? "true" : "false"; return *this; }
  JsonWriter& Value(const std::string& key, const std::string& v) { Key(key); String(v); return *this; }
  JsonWriter& Value(const std::string& key, const char* v) { return Value(key, std::string(v)); }
  // Array elements.
  JsonWriter& Element(double v) { Key(""); Number(v); return *this; }

  const std::string& str() const { return out_; }

 private:
  void Key(const std::string& key) {
    if (!first_.empty()) {
      if (!first_.back()) out_ += ",";
      first_.back() = false;
      out_ += "\n" + std::string(2 * first_.size(), ' ');
    }
    if (!key.empty()) {
      String(key);
      out_ += ": ";
    }
  }
  void Open(const std::string& key, char bracket) {
    Key(key);
    out_ += bracket;
    first_.push_back(true);
  }
  void Close(char bracket) {
    const bool empty = first_.back();
    first_.pop_back();
    if (!empty) out_ += "\n" + std::string(2 * first_.size(), ' ');
    out_ += bracket;
  }
  void Number(double v) {
    if (!std::isfinite(v)) {
      out_ += "null";
      return;
    }
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.17g", v);
    out_ += buf;
  }
  void String(const std::string& s) {
    out_ += '"';
    for (unsigned char c : s) {
      switch (c) {
        case '"': out_ += "\\\""; break;
        case '\\': out_ += "\\\\"; break;
        case '\n': out_ += "\\n"; break;
        case '\t': out_ += "\\t"; break;
        case '\r': out_ += "\\r"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", c);
            out_ += buf;
          } else {
            out_ += static_cast<char>(c);
          }
      }
    }
    out_ += '"';
  }

  std::string out_;
  std::vector<bool> first_;
};

}  // namespace arview::app
