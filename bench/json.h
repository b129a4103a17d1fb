// One JSON object per line: JsonLine().str("bench", "bvh").num("build_ms", 1.5).print();
// Every line names its "bench" and the "device" that ran it; with --record, print() also
// appends the line to bench/results/<benchmark>.jsonl (bench/record.cpp).
#pragma once
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace osr::bench {

// --record: from now on, append each printed line to bench/results/<benchmark>.jsonl in the
// source tree with "date", "commit" and "machine" first. Throws InputError if it cannot open it.
void startRecording(const std::string& benchmark);
// Appends {date, commit, machine, body} as one line, atomically; nothing when not recording.
void recordLine(const std::string& body);

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
  JsonLine& integers(const char* key, const std::vector<long long>& values) {
    std::string list = "[";
    for (size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + std::to_string(values[i]);
    return raw(key, list + "]");
  }
  void print() const {
    std::printf("{%s}\n", body_.c_str());
    std::fflush(stdout);
    recordLine(body_);
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
