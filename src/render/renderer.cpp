#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "render/trace_pass.h"
#include "vk/timer.h"

namespace osr::render {

namespace pt = gpu::pt;

namespace {

gpu::camera::CameraFrame makeFrame(const scene::Camera& camera, const RenderSettings& s) {
  gpu::camera::CameraFrame f{};
  const glm::mat4& m = camera.worldFromCamera;
  f.cameraRight = glm::vec4(glm::normalize(glm::vec3(m[0])), 0.f);
  f.cameraUp = glm::vec4(glm::normalize(glm::vec3(m[1])), 0.f);
  f.cameraBack = glm::vec4(glm::normalize(glm::vec3(m[2])), 0.f);
  f.cameraOrigin = glm::vec4(glm::vec3(m[3]), 1.f);
  f.width = s.width;
  f.height = s.height;
  f.seed = s.seed;
  f.tanHalfFovY = std::tan(0.5f * camera.yfov);
  f.aspect = float(s.width) / float(s.height);
  return f;
}

}  // namespace

FilmLayers render(const vk::Context& ctx, const scene::GpuScene& scene, const bvh::Bvh& bvh,
                  const scene::Camera& camera, const RenderSettings& settings,
                  const std::function<void(const Progress&)>& onProgress, RenderStats* stats) {
  Film film(ctx, settings.width, settings.height);
  vk::Buffer frame(ctx, sizeof(gpu::camera::CameraFrame), vk::MemoryUse::DeviceLocal, "pt frame");
  gpu::camera::CameraFrame f = makeFrame(camera, settings);
  frame.upload(&f, sizeof f);
  TracePass pass(ctx, settings.integrator, scene.features, scene.texelFetch);
  vk::GpuTimer timer(ctx, 1);
  double gpuMs = 0.0;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { film.recordClear(cmd); });

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  uint32_t done = 0;
  uint32_t batch = 1;
  double secondsPerSample = 0.0;
  while (done < settings.spp) {
    double now = elapsed();
    // Stop when one more sample would end nearer past the budget than we are before it.
    if (settings.timeLimitS > 0.0 && done > 0 &&
        now + 0.5 * secondsPerSample >= settings.timeLimitS)
      break;
    uint32_t n = std::min(batch, settings.spp - done);
    if (settings.timeLimitS > 0.0 && secondsPerSample > 0.0) {
      // Do not plan past the time budget (at least one sample per batch).
      double left = settings.timeLimitS - now;
      n = std::max<uint32_t>(1, std::min<uint32_t>(n, uint32_t(left / secondsPerSample)));
    }
    const double t0 = elapsed();
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      vk::TimedScope scope(&timer, cmd, "pt_trace");
      pass.record(cmd, {&film, &frame, &bvh, &scene, done, n});
    });
    gpuMs += timer.totalMs("pt_trace");
    const double dt = elapsed() - t0;
    done += n;
    secondsPerSample = dt / n;
    // Grow or shrink the batch towards the target submission length.
    batch = std::clamp<uint32_t>(uint32_t(settings.batchTargetS / std::max(secondsPerSample, 1e-6)),
                                 1u, 1024u);
    if (onProgress) {
      Progress p;
      p.samples = done;
      p.targetSamples = settings.spp;
      p.elapsedS = elapsed();
      double bySamples = (settings.spp - done) * secondsPerSample;
      p.remainingS = settings.timeLimitS > 0.0
                         ? std::max(0.0, std::min(bySamples, settings.timeLimitS - p.elapsedS))
                         : bySamples;
      onProgress(p);
    }
  }
  if (stats) {
    stats->samples = done;
    stats->seconds = elapsed();
    stats->gpuMs = gpuMs;
  }
  return film.resolve();
}

}  // namespace osr::render
