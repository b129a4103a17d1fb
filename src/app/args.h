// A small command-line reader shared by every osr-vk subcommand: options are declared by
// asking for them, then finish() rejects anything left over, so an unknown or misspelt flag
// is an InputError (exit 2), never silently ignored.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace osr::app {

class Args {
 public:
  Args(std::vector<std::string> args, std::string command);

  // True if `name` (e.g. "--quiet") is present; consumes it.
  bool flag(const std::string& name);
  // Value following `name` ("--width 512" or "--width=512"); consumes both. An option given
  // twice is an InputError.
  std::optional<std::string> value(const std::string& name);
  std::optional<long long> integer(const std::string& name, long long min, long long max);
  std::optional<double> number(const std::string& name, double min, double max);
  // Integers joined by `separator` ("--batch 64,256", "--tile 4x8"), each in [min, max].
  std::optional<std::vector<long long>> integerList(const std::string& name, long long min,
                                                    long long max, char separator = ',');
  // Remaining non-option arguments, in order; consumes them.
  std::vector<std::string> positional();
  // Throws InputError naming the first unconsumed argument.
  void finish() const;

 private:
  long long parseInteger(const std::string& name, const std::string& text, long long min,
                         long long max) const;
  std::vector<std::string> args_;
  std::vector<bool> used_;
  std::string command_;
};

// True if "--help" or "-h" is anywhere in `args`: the caller prints its usage on stdout and
// exits 0 whatever else is there, so help works after a subcommand and among other options.
bool helpRequested(const std::vector<std::string>& args);

}  // namespace osr::app
