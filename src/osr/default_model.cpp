#include "osr/default_model.h"

#ifdef OSR_DEFAULT_MODEL_FILE
// The file's bytes, placed by the assembler (.incbin) rather than as a megabyte-long array
// literal for the compiler; CMake recompiles this file when the model changes.
#define OSR_STR2(x) #x
#define OSR_STR(x) OSR_STR2(x)
asm(".section .rodata\n"
    ".balign 64\n"
    ".global osr_default_model_begin\n"
    "osr_default_model_begin:\n"
    ".incbin \"" OSR_STR(OSR_DEFAULT_MODEL_FILE) "\"\n"
    ".global osr_default_model_end\n"
    "osr_default_model_end:\n"
    ".previous\n");
extern "C" const uint8_t osr_default_model_begin[];
extern "C" const uint8_t osr_default_model_end[];
#endif

namespace osr::oneshot {

std::span<const uint8_t> defaultModelBytes() {
#ifdef OSR_DEFAULT_MODEL_FILE
  return {osr_default_model_begin, size_t(osr_default_model_end - osr_default_model_begin)};
#else
  return {};
#endif
}

}  // namespace osr::oneshot
