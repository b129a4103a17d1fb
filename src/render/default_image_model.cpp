#include "render/default_image_model.h"

#include "common/embedded_file.h"

#ifdef OSR_DEFAULT_IMAGE_MODEL_FILE
OSR_EMBED_FILE(osr_default_image_model, OSR_DEFAULT_IMAGE_MODEL_FILE)
#endif

namespace osr::render {

std::span<const uint8_t> defaultImageModelBytes() {
#ifdef OSR_DEFAULT_IMAGE_MODEL_FILE
  return {osr_default_image_model_begin,
          size_t(osr_default_image_model_end - osr_default_image_model_begin)};
#else
  return {};
#endif
}

}  // namespace osr::render
