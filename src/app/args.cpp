#include "app/args.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/error.h"

namespace osr::app {

namespace {
// A bound as a person writes it: 0.001, 10000000, 16777216 (not 0.001000 or 1e+07).
std::string plainNumber(double x) {
  if (x == std::floor(x) && std::fabs(x) < 1e15) return std::to_string((long long)x);
  char buf[64];
  // The shortest text that reads back as the same double.
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}
}  // namespace

Args::Args(std::vector<std::string> args, std::string command)
    : args_(std::move(args)), used_(args_.size(), false), command_(std::move(command)) {}

bool Args::flag(const std::string& name) {
  bool found = false;
  for (size_t i = 0; i < args_.size(); ++i)
    if (!used_[i] && args_[i] == name) used_[i] = found = true;
  return found;
}

std::optional<std::string> Args::value(const std::string& name) {
  std::optional<std::string> result;
  for (size_t i = 0; i < args_.size(); ++i) {
    if (used_[i]) continue;
    std::optional<std::string> found;
    if (args_[i] == name) {
      if (i + 1 >= args_.size())
        throw InputError(command_ + ": option " + name + " needs a value");
      used_[i] = used_[i + 1] = true;
      found = args_[i + 1];
      ++i;
    } else if (args_[i].rfind(name + "=", 0) == 0) {
      used_[i] = true;
      found = args_[i].substr(name.size() + 1);
    }
    // A second value would silently replace the first (`--offline a.exr --offline b.exr`
    // writes no a.exr): refuse it rather than guess which one the user meant.
    if (found && result)
      throw InputError(command_ + ": option " + name + " given twice ('" + *result + "', '" +
                       *found + "')");
    if (found) result = std::move(found);
  }
  return result;
}

std::optional<long long> Args::integer(const std::string& name, long long min, long long max) {
  auto v = value(name);
  if (!v) return std::nullopt;
  return parseInteger(name, *v, min, max);
}

std::optional<std::vector<long long>> Args::integerList(const std::string& name, long long min,
                                                        long long max, char separator) {
  auto v = value(name);
  if (!v) return std::nullopt;
  std::vector<long long> out;
  size_t start = 0;
  for (size_t end; (end = v->find(separator, start)) != std::string::npos; start = end + 1)
    out.push_back(parseInteger(name, v->substr(start, end - start), min, max));
  out.push_back(parseInteger(name, v->substr(start), min, max));
  return out;
}

long long Args::parseInteger(const std::string& name, const std::string& text, long long min,
                             long long max) const {
  errno = 0;
  char* end = nullptr;
  long long x = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end || errno)
    throw InputError(command_ + ": option " + name + " expects an integer, got '" + text + "'");
  if (x < min || x > max)
    throw InputError(command_ + ": option " + name + " must be in [" + std::to_string(min) +
                     ", " + std::to_string(max) + "], got " + text);
  return x;
}

std::optional<double> Args::number(const std::string& name, double min, double max) {
  auto v = value(name);
  if (!v) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  double x = std::strtod(v->c_str(), &end);
  if (v->empty() || *end || errno || !std::isfinite(x))
    throw InputError(command_ + ": option " + name + " expects a number, got '" + *v + "'");
  if (x < min || x > max)
    throw InputError(command_ + ": option " + name + " must be in [" + plainNumber(min) + ", " +
                     plainNumber(max) + "], got " + *v);
  return x;
}

std::vector<std::string> Args::positional() {
  std::vector<std::string> out;
  for (size_t i = 0; i < args_.size(); ++i)
    if (!used_[i] && (args_[i].empty() || args_[i][0] != '-' || args_[i] == "-")) {
      used_[i] = true;
      out.push_back(args_[i]);
    }
  return out;
}

void Args::finish() const {
  for (size_t i = 0; i < args_.size(); ++i)
    if (!used_[i])
      throw InputError(command_ + ": unknown option '" + args_[i] + "' (see --help)");
}

bool helpRequested(const std::vector<std::string>& args) {
  return std::any_of(args.begin(), args.end(),
                     [](const std::string& a) { return a == "--help" || a == "-h"; });
}

}  // namespace osr::app
