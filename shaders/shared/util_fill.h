// util_fill.comp: writes one 32-bit value into a range of a buffer (clears, test patterns).
#ifndef OSR_SHARED_UTIL_FILL_H
#define OSR_SHARED_UTIL_FILL_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(util_fill)
OSR_CONST(uint, kWorkgroupSize, 64);
OSR_CONST(uint, kBindingData, 0);
struct Push {
  uint count;  // number of 32-bit words to write, from word 0
  uint value;  // bit pattern written
};
OSR_NAMESPACE_END
#endif
