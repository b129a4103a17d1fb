#version 460
// denoise_net_input: one tile of the image denoiser's input tensor (9 x tileHeight x
// tileWidth, NCHW fp32, src/nn_kernels/image_unet.h) from the image layers:
// log1p(e * max(colour, 0)), albedo, normal, e from denoise_exposure. Pixels of the padding
// repeat the image's last row and column (docs/denoise.md "Padding").
#extension GL_GOOGLE_include_directive : require
#include "shared/denoise.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(std430, binding = kBindingColour) readonly buffer Colour { vec4 gColour[]; };
layout(std430, binding = kBindingAlbedo) readonly buffer Albedo { vec4 gAlbedo[]; };
layout(std430, binding = kBindingNormal) readonly buffer Normal { vec4 gNormal[]; };
layout(std430, binding = kBindingExposure) readonly buffer Sums { ExposureSums gSums[]; };
layout(std430, binding = kBindingTensor) writeonly buffer Tensor { float gTensor[]; };
layout(push_constant) uniform PushBlock { DenoisePush gPush; };

void main() {
  const uvec2 t = gl_GlobalInvocationID.xy;
  if (t.x >= gPush.tileWidth || t.y >= gPush.tileHeight) return;
  const uint x = min(gPush.tileX + t.x, gPush.width - 1);
  const uint y = min(gPush.tileY + t.y, gPush.height - 1);
  const uint p = y * gPush.width + x;
  const float e = gSums[kExposurePartials].exposure;
  const vec3 c = log(1.0 + e * max(gColour[p].rgb, vec3(0.0)));
  const vec3 a = gAlbedo[p].rgb, n = gNormal[p].xyz;
  const uint plane = gPush.tileWidth * gPush.tileHeight, o = t.y * gPush.tileWidth + t.x;
  for (uint ch = 0u; ch < 3u; ++ch) {
    gTensor[ch * plane + o] = c[ch];
    gTensor[(3u + ch) * plane + o] = a[ch];
    gTensor[(6u + ch) * plane + o] = n[ch];
  }
}
