#include "osr/default_model.h"

#include "common/embedded_file.h"

#ifdef OSR_DEFAULT_MODEL_FILE
OSR_EMBED_FILE(osr_default_model, OSR_DEFAULT_MODEL_FILE)
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
