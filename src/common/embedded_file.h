// A file's bytes built into the executable: OSR_EMBED_FILE(name, path) places them in .rodata
// by the assembler (.incbin), not as an array literal for the compiler, and declares
// name_begin / name_end. CMake passes `path` as a compile definition of the embedding source
// and recompiles it when the file changes (OBJECT_DEPENDS).
#pragma once
#include <cstdint>

#define OSR_EMBED_STR2(x) #x
#define OSR_EMBED_STR(x) OSR_EMBED_STR2(x)
#define OSR_EMBED_FILE(name, path)                                                              \
  asm(".section .rodata\n.balign 64\n.global " #name "_begin\n" #name "_begin:\n.incbin \"" \
      OSR_EMBED_STR(path) "\"\n.global " #name "_end\n" #name "_end:\n.previous\n");        \
  extern "C" const uint8_t name##_begin[];                                                    \
  extern "C" const uint8_t name##_end[];
