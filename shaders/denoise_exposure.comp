#version 460
// denoise_exposure: the image denoiser's exposure scale e, as tools/image_unet.py's
// image_exposure computes it over the padded image: 0.18 / exp(mean log(1e-4 + luminance))
// over pixels with luminance > 0, 1 when there are none. Stage 0 (kExposurePartials
// workgroups): each workgroup's sum and count; stage 1 (one workgroup): their total and e,
// stored after the partials. Shared-memory tree sums: no subgroup size assumed.
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"

layout(local_size_x = kDenoiseWorkgroup) in;
layout(constant_id = kSpecExposureStage) const uint kStage = 0;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingExposure) buffer Sums { ExposureSums gSums[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

shared float sLog[kDenoiseWorkgroup];
shared uint sCount[kDenoiseWorkgroup];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  float logSum = 0.0;
  uint count = 0u;
  if (kStage == 0u) {
    const uint n = gPush.paddedWidth * gPush.paddedHeight;
    for (uint i = gl_GlobalInvocationID.x; i < n; i += kExposurePartials * kDenoiseWorkgroup) {
      // Padding repeats the last row and column, as the network sees it.
      const uint x = min(i % gPush.paddedWidth, gPush.width - 1);
      const uint y = min(i / gPush.paddedWidth, gPush.height - 1);
      const vec3 c = gColour[y * gPush.width + x].rgb;
      const float lum = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
      if (lum > 0.0) {
        logSum += log(1e-4 + lum);
        count += 1u;
      }
    }
  } else {
    for (uint i = lane; i < kExposurePartials; i += kDenoiseWorkgroup) {
      logSum += gSums[i].logSum;
      count += gSums[i].count;
    }
  }
  sLog[lane] = logSum;
  sCount[lane] = count;
  barrier();
  for (uint s = kDenoiseWorkgroup / 2u; s > 0u; s >>= 1u) {
    if (lane < s) {
      sLog[lane] += sLog[lane + s];
      sCount[lane] += sCount[lane + s];
    }
    barrier();
  }
  if (lane == 0u) {
    ExposureSums r;
    r.logSum = sLog[0];
    r.count = sCount[0];
    r.exposure = r.count > 0u ? kExposureKey / exp(r.logSum / float(r.count)) : 1.0;
    r._pad0 = 0u;
    gSums[kStage == 0u ? gl_WorkGroupID.x : kExposurePartials] = r;
  }
}
