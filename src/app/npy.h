// NumPy .npy files (format 1.0) without NumPy: little-endian float32 or int32 C-order arrays,
// the header padded so the data starts on a 64-byte boundary (numpy.load(mmap_mode='r') maps
// it without a copy).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace osr::app::npy {

// Writes the file at `path`: magic, version 1.0, header length, header dict, then the data.
// `descr` is "<f4" or "<i4"; `shape`'s product times 4 must equal `bytes`. Throws
// std::runtime_error naming the path when it cannot be written.
void write(const std::string& path, const char* descr, const std::vector<uint64_t>& shape,
           const void* data, size_t bytes);

// `{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }` padded with spaces and a
// newline so that 10 + its length is a multiple of 64.
std::string header(const char* descr, const std::vector<uint64_t>& shape);

}  // namespace osr::app::npy
