#include "render/temporal_reuse.h"

#include <chrono>
#include <cstring>

#include "common/error.h"
#include "shaders/shared/temporal.h"
#include "vk/binder.h"

namespace osr::render {

namespace g = gpu::temporal;

namespace {

// The head of save()'s bytes; the history's five layers follow it.
struct SavedHistory {
  char magic[8];
  uint32_t width, height;
  float maxHistory;
  int32_t frame;
  uint64_t key;
  gpu::camera::CameraFrame camera;
};
constexpr char kSavedMagic[8] = {'O', 'S', 'R', 'T', 'R', 'H', '0', '1'};

}  // namespace

TemporalReuse::TemporalReuse(const vk::Context& ctx, uint32_t width, uint32_t height, float maxHistory)
    : ctx_(ctx),
      width_(width),
      height_(height),
      maxHistory_(maxHistory),
      pipeline_(ctx, shaders::Id::film_temporal, g::kTemporalBindingCount, sizeof(g::TemporalPush)),
      cameras_(ctx, sizeof(g::TemporalCameras), vk::MemoryUse::DeviceLocal, "temporal cameras") {
  const uint64_t bytes = wholeLayerBytes(ctx, width, height, "temporal reuse");
  frameColour_ = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "temporal frame colour");
  for (Layers& l : layers_)
    for (vk::Buffer* b : l.all())
      *b = vk::Buffer(ctx, bytes, vk::MemoryUse::DeviceLocal, "temporal layer");
}

void TemporalReuse::apply(FilmLayers& film, const gpu::camera::CameraFrame& camera) {
  if (film.width != int(width_) || film.height != int(height_))
    throw DeviceError("temporal reuse: film size does not match");
  const auto start = std::chrono::steady_clock::now();
  const size_t n = size_t(width_) * height_;
  Layers& now = layers_[current_];
  const Layers& before = layers_[current_ ^ 1];
  now.combined.uploadVector(vec4Layer(film.combined, film.variance));
  now.direct.uploadVector(vec4Layer(film.direct, {}));
  now.indirect.uploadVector(vec4Layer(film.indirect, {}));
  now.albedo.uploadVector(vec4Layer(film.albedo, film.depth));
  now.normal.uploadVector(vec4Layer(film.normal, film.light));
  const g::TemporalCameras cams{camera, hasHistory_ ? previousCamera_ : camera};
  cameras_.upload(&cams, sizeof cams);

  g::TemporalPush push{};
  push.width = width_;
  push.height = height_;
  push.samples = float(std::max(film.samples, 1u));
  // Without history the pass only writes the counts: no pixel takes anything. Under a camera
  // that did not move nothing lags behind (the light is the same, seen from the same place),
  // so the frames add up without a cap, as one render's samples do.
  const bool still = hasHistory_ && std::memcmp(&camera, &previousCamera_, sizeof camera) == 0;
  push.maxHistory = !hasHistory_ ? 0.0f : still ? 1e30f : maxHistory_;
  push.rejectSigma = 3.0f;
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    // The neighbourhood the history is tested against: the colour as uploaded, copied on the
    // device, since the pass blends into now.combined in place.
    const VkBufferCopy whole{0, 0, VkDeviceSize(n) * 16};
    vkCmdCopyBuffer(cmd, now.combined.handle(), frameColour_.handle(), 1, &whole);
    vk::transferBarrier(cmd);
    vk::Binder(pipeline_)
        .set(g::kBindingCombined, now.combined)
        .set(g::kBindingDirect, now.direct)
        .set(g::kBindingIndirect, now.indirect)
        .set(g::kBindingAlbedo, now.albedo)
        .set(g::kBindingNormal, now.normal)
        .set(g::kBindingHistoryCombined, before.combined)
        .set(g::kBindingHistoryDirect, before.direct)
        .set(g::kBindingHistoryIndirect, before.indirect)
        .set(g::kBindingHistoryAlbedo, before.albedo)
        .set(g::kBindingHistoryNormal, before.normal)
        .set(g::kBindingCameras, cameras_)
        .set(g::kBindingFrameColour, frameColour_)
        .bind(cmd, push);
    pipeline_.dispatch(cmd, (width_ + g::kTemporalTile - 1) / g::kTemporalTile,
                       (height_ + g::kTemporalTile - 1) / g::kTemporalTile);
  });
  if (film.variance.size() != n) film.variance.assign(n, 0.0f);
  fromVec4Layer(now.combined.downloadVector<float>(n * 4), film.combined, &film.variance);
  fromVec4Layer(now.direct.downloadVector<float>(n * 4), film.direct);
  const std::vector<float> indirect = now.indirect.downloadVector<float>(n * 4);
  fromVec4Layer(indirect, film.indirect);
  size_t reused = 0;
  for (size_t i = 0; i < n; ++i) reused += indirect[4 * i + 3] > push.samples;
  reusedShare_ = double(reused) / double(n);
  previousCamera_ = camera;
  hasHistory_ = true;
  current_ ^= 1;
  lastSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<uint8_t> TemporalReuse::save(int frame, uint64_t key) const {
  if (!hasHistory_) return {};
  SavedHistory head{};
  std::memcpy(head.magic, kSavedMagic, sizeof kSavedMagic);
  head.width = width_;
  head.height = height_;
  head.maxHistory = maxHistory_;
  head.frame = frame;
  head.key = key;
  head.camera = previousCamera_;
  const size_t layerBytes = size_t(width_) * height_ * 16;
  std::vector<uint8_t> bytes(sizeof head + 5 * layerBytes);
  std::memcpy(bytes.data(), &head, sizeof head);
  const Layers& history = layers_[current_ ^ 1];
  uint8_t* at = bytes.data() + sizeof head;
  for (const vk::Buffer* b : history.all()) {
    b->download(at, layerBytes);
    at += layerBytes;
  }
  return bytes;
}

bool TemporalReuse::restore(const std::vector<uint8_t>& bytes, int frame, uint64_t key) {
  const size_t layerBytes = size_t(width_) * height_ * 16;
  SavedHistory head{};
  if (bytes.size() != sizeof head + 5 * layerBytes) return false;
  std::memcpy(&head, bytes.data(), sizeof head);
  if (std::memcmp(head.magic, kSavedMagic, sizeof kSavedMagic) != 0 || head.width != width_ ||
      head.height != height_ || head.maxHistory != maxHistory_ || head.frame != frame || head.key != key)
    return false;
  Layers& history = layers_[current_ ^ 1];
  const uint8_t* at = bytes.data() + sizeof head;
  for (vk::Buffer* b : history.all()) {
    b->upload(at, layerBytes);
    at += layerBytes;
  }
  previousCamera_ = head.camera;
  hasHistory_ = true;
  return true;
}

}  // namespace osr::render
