#include "render/flicker.h"

#include <cmath>
#include <glm/glm.hpp>
#include <stdexcept>

#include "image/image_metrics.h"

namespace osr::render {

namespace {

// The world point pixel (x, y)'s centre sees at view-axis depth d (lib/camera.glsl cameraRay
// without the filter jitter).
glm::vec3 pointOfPixel(const gpu::camera::CameraFrame& f, uint32_t x, uint32_t y, float d) {
  const float ndcX = (float(x) + 0.5f) / float(f.width) * 2.f - 1.f;
  const float ndcY = 1.f - (float(y) + 0.5f) / float(f.height) * 2.f;
  const glm::vec3 local(ndcX * f.tanHalfFovY * f.aspect, ndcY * f.tanHalfFovY, -1.f);
  return glm::vec3(f.cameraOrigin) +
         d * (local.x * glm::vec3(f.cameraRight) + local.y * glm::vec3(f.cameraUp) +
              local.z * glm::vec3(f.cameraBack));
}

// Whether 1 / depth around (x, y) is affine within 2%: one surface, no silhouette or blend.
bool smoothDepth(const std::vector<float>& depth, uint32_t w, uint32_t h, uint32_t x, uint32_t y) {
  if (x == 0 || y == 0 || x + 1 >= w || y + 1 >= h) return false;
  auto inv = [&](uint32_t px, uint32_t py) {
    const float d = depth[size_t(py) * w + px];
    return d > 0.f ? 1.f / d : -1.f;
  };
  const float c = inv(x, y);
  const float l = inv(x - 1, y), r = inv(x + 1, y), u = inv(x, y - 1), b = inv(x, y + 1);
  if (c <= 0.f || l <= 0.f || r <= 0.f || u <= 0.f || b <= 0.f) return false;
  return std::abs(l + r - 2.f * c) <= 0.02f * c && std::abs(u + b - 2.f * c) <= 0.02f * c;
}

}  // namespace

std::vector<PixelPair> reprojectPairs(const DepthView& current, const DepthView& previous) {
  const gpu::camera::CameraFrame& cf = current.camera;
  const gpu::camera::CameraFrame& pf = previous.camera;
  const uint32_t w = cf.width, h = cf.height;
  if (pf.width != w || pf.height != h || !current.depth || !previous.depth ||
      current.depth->size() != size_t(w) * h || previous.depth->size() != size_t(w) * h)
    throw std::invalid_argument("reprojectPairs: views of different sizes or without depth");
  std::vector<PixelPair> pairs;
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      if (!smoothDepth(*current.depth, w, h, x, y)) continue;
      const glm::vec3 p = pointOfPixel(cf, x, y, (*current.depth)[size_t(y) * w + x]);
      // lib/camera.glsl cameraProject into the previous view.
      const glm::vec3 d = p - glm::vec3(pf.cameraOrigin);
      const float z = -glm::dot(d, glm::vec3(pf.cameraBack));
      if (!(z > 0.f)) continue;
      const float ndcX = glm::dot(d, glm::vec3(pf.cameraRight)) / (z * pf.tanHalfFovY * pf.aspect);
      const float ndcY = glm::dot(d, glm::vec3(pf.cameraUp)) / (z * pf.tanHalfFovY);
      const float px = (ndcX + 1.f) * 0.5f * float(w), py = (1.f - ndcY) * 0.5f * float(h);
      if (!(px >= 0.f && py >= 0.f && px < float(w) && py < float(h))) continue;
      const uint32_t qx = uint32_t(px), qy = uint32_t(py);
      const float dq = (*previous.depth)[size_t(qy) * w + qx];
      if (!(dq > 0.f) || std::abs(dq - z) > 0.01f * z) continue;
      pairs.push_back({y * w + x, qy * w + qx});
    }
  }
  return pairs;
}

double flicker(const std::vector<PixelPair>& pairs, const std::vector<float>& current,
               const std::vector<float>& previous, const std::vector<float>& norm) {
  if (pairs.empty()) return 0.0;
  double sum = 0.0;
  for (const PixelPair& pp : pairs) {
    for (int c = 0; c < 3; ++c) {
      const double a = current[size_t(pp.current) * 3 + c];
      const double b = previous[size_t(pp.previous) * 3 + c];
      const double n = norm[size_t(pp.current) * 3 + c];
      sum += (a - b) * (a - b) / (n * n + image::kRelMseEpsilon);
    }
  }
  return sum / (3.0 * double(pairs.size()));
}

}  // namespace osr::render
