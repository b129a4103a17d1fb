#version 460
// denoise_net_output: the image denoiser's output y (3 x tileHeight x tileWidth, NCHW fp32)
// back to colour, expm1(max(y, 0)) / e, for the tile's core pixels inside the image (the
// margin around the core only fed the receptive field). w is 0.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(std430, binding = kBindingExposure) readonly buffer Sums { ExposureSums gSums[]; };
layout(std430, binding = kBindingTensor) readonly buffer Tensor { float gTensor[]; };
layout(std430, binding = kBindingOut) writeonly buffer Out { vec4 gOut[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

void main() {
  const uint x = gPush.coreX0 + gl_GlobalInvocationID.x, y = gPush.coreY0 + gl_GlobalInvocationID.y;
  if (x >= gPush.coreX1 || y >= gPush.coreY1) return;
  const float e = gSums[kExposurePartials].exposure;
  const uint plane = gPush.tileWidth * gPush.tileHeight;
  const uint o = (y - gPush.tileY) * gPush.tileWidth + (x - gPush.tileX);
  const vec3 v = vec3(gTensor[o], gTensor[plane + o], gTensor[2u * plane + o]);
  gOut[y * gPush.width + x] = vec4((exp(max(v, vec3(0.0))) - 1.0) / e, 0.0);
}
