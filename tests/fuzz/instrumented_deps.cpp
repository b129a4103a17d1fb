// Built only into the libFuzzer executables (-DOSR_FUZZ=ON): tinygltf's and stb_image's code
// from the same headers as the system libraries, compiled here with coverage and sanitizers so
// that the fuzzer sees its way through the JSON parser and the image decoders into the
// loader's own checks. The executable's definitions take precedence over libtinygltf.so's and
// libstb.so's.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE  // included below from Debian's stb/ folder
#include <stb/stb_image.h>
#include <tiny_gltf.h>
