// One JSON object per line: JsonLine().str("bench", "bvh").num("build_ms", 1.5).print();
#pragma once
#include <cmath>
#include <cstdio>
#include <string>

namespace osr::bench {

class JsonLine {
 public:
  JsonLine& str(const char* key, const std::string& value) {
    std::string escaped;
    for (char c : value) {
      if (c == '"' || c == '\\') escaped += '\\';
      escaped += c;
    }
    return raw(key, "\"" + escaped + "\"");
  }
  JsonLine& num(const char* key, double value) {
    if (!std::isfinite(value)) return raw(key, "null");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", value);
    return raw(key, buf);
  }
  JsonLine& integer(const char* key, long long value) { return raw(key, std::to_string(value)); }
  void print() const {
    std::printf("{%s}\n", body_.c_str());
    std::fflush(stdout);
  }

 private:
  JsonLine& raw(const char* key, const std::string& v) {
    if (!body_.empty()) body_ += ", ";
    body_ += "\"" + std::string(key) + "\": " + v;
    return *this;
  }
  std::string body_;
};

}  // namespace osr::bench
