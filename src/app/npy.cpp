#include "app/npy.h"

#include <bit>
#include <fstream>
#include <stdexcept>

namespace osr::app::npy {

static_assert(std::endian::native == std::endian::little, "npy: writes the host's byte order");

std::string header(const char* descr, const std::vector<uint64_t>& shape) {
  std::string dims;
  for (uint64_t d : shape) dims += std::to_string(d) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 2);   // (2, 3); a 1-d shape keeps "(2,)"
  else if (shape.size() == 1) dims.pop_back();
  std::string h = std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" +
                  dims + "), }";
  const size_t total = 10 + h.size() + 1;  // magic 6 + version 2 + length 2, dict, '\n'
  h.append((64 - total % 64) % 64, ' ');
  h += '\n';
  return h;
}

void write(const std::string& path, const char* descr, const std::vector<uint64_t>& shape,
           const void* data, size_t bytes) {
  uint64_t elements = 1;
  for (uint64_t d : shape) elements *= d;
  if (elements * 4 != bytes) throw std::logic_error("npy: shape does not match the data size");
  const std::string h = header(descr, shape);
  if (h.size() > 0xffff) throw std::logic_error("npy: header too long for format 1.0");
  const char preamble[10] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0, char(h.size() & 0xff),
                             char(h.size() >> 8)};
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(preamble, sizeof preamble);
  f.write(h.data(), std::streamsize(h.size()));
  f.write(static_cast<const char*>(data), std::streamsize(bytes));
  f.close();
  if (!f) throw std::runtime_error(path + ": cannot write");
}

}  // namespace osr::app::npy
