#include "app/maps_file.h"

#include <fstream>
#include <iterator>

#include "common/error.h"
#include "common/input_file.h"
#include "nn_kernels/weights_format.h"

namespace osr::app {

MapsFile readMapsFile(const std::string& path) {
  if (auto problem = inputFileProblem(path)) throw InputError(path + ": " + *problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open input maps");
  MapsFile f;
  f.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const size_t mapBytes = size_t(nn::kInChannels) * nn::kMapSize * nn::kMapSize * 4;
  if (f.bytes.empty() || f.bytes.size() % mapBytes)
    throw InputError(path + ": " + std::to_string(f.bytes.size()) +
                     " bytes is not a positive multiple of one 7x32x32 fp32 map (" +
                     std::to_string(mapBytes) + " bytes)");
  f.maps = uint32_t(f.bytes.size() / mapBytes);
  return f;
}

}  // namespace osr::app
