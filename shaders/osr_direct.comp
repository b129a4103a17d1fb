#version 460
// osr_direct: light that reaches the G-buffer surface in one hop, several samples per pixel:
// next-event estimation combined with BSDF sampling by the power heuristic (lib/path.glsl's
// estimator, first bounce only), times the specular chain's throughput. Adds one pass's
// average to AccumPixel.direct (w counts passes; osr_gbuffer has added emission seen), and
// the samples' luminance and its square to AccumPixel.depth.w and normal.w: the denoisers'
// variance (osr_resolve) then holds the direct light's noise, most of OSR's pixel noise in
// the first passes.
// In: GBufferPixel, scene, BVH. Out: AccumPixel.direct, depth.w, normal.w.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { DirectPush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  GBufferPixel g = gGBuffer[local];
  vec3 sum = vec3(0.0);
  float sumLum = 0.0, sumLumSq = 0.0;  // over the samples, of lum(throughput x sample) and its square
  if (g.position.w > 0.5) {
    ShadingPoint sp = gbufferShadingPoint(g);
    Rng rng = pixelRng(gPush.pass, pixel, kSaltDirect);
    for (uint i = 0u; i < gPush.lightSamples; ++i) {
      vec3 value = estimateDirect(sp, rngNext3(rng));
      // The BSDF-sampled half of MIS: a light hit by the sampled direction.
      PathState p = pathStart(sp.position, vec3(0.0), vec3(1.0), 0.0, sp.position, 1u);
      BsdfSample bs;
      bool sampled = bsdfSample(sp.bsdf, sp.woLocal, rngNext3(rng), bs);
      vec3 wi = sampled ? toWorld(bs.wi, sp.t, sp.b, sp.ns) : vec3(0.0);
      if (sampled && (dot(wi, sp.ng) > 0.0) == (bs.wi.z > 0.0)) {
        p.origin = shadingRayOrigin(sp, wi);
        p.dir = wi;
        p.beta = bs.weight;
        p.prevPdf = bs.delta ? 0.0 : bs.pdf;
        Hit hit;
        if (!bvhClosestHit(p.origin, p.dir, 0.0, kInfinity, hit)) {
          value += missRadiance(p);
        } else {
          SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
          value += hitEmission(p, hit.triangle, surf, shadingPoint(surf, -wi));
        }
      }
      sum += value;
      float lum = luminance(g.throughput.rgb * value);
      sumLum += lum;
      sumLumSq += lum * lum;
    }
    sum *= g.throughput.rgb / float(max(gPush.lightSamples, 1u));
  }
  // Weighted by the pass's light samples: passes of 4 samples after passes of 16 would
  // otherwise add more noise than they remove.
  float weight = float(max(gPush.lightSamples, 1u));
  AccumPixel a = gAccum[local];
  if (finite3(sum)) {
    a.direct.rgb += weight * sum;
    a.depth.w += sumLum;
    a.normal.w += sumLumSq;
  }
  a.direct.w += weight;
  gAccum[local] = a;
}
