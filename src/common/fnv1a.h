// FNV-1a, 64 bits, over bytes added in turn: the keys that tell whether something kept on disk
// was made from the same inputs (osr-bench animation's references, a shot's temporal history).
#pragma once
#include <cstdint>
#include <string_view>

namespace osr {

class Fnv1a {
 public:
  Fnv1a& add(std::string_view bytes) {
    for (const char c : bytes) hash_ = (hash_ ^ uint8_t(c)) * kPrime;
    return *this;
  }
  uint64_t value() const { return hash_; }

 private:
  static constexpr uint64_t kPrime = 1099511628211ull;
  uint64_t hash_ = 1469598103934665603ull;
};

}  // namespace osr
