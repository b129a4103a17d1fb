#version 460
// osr_composite: each pixel's indirect light from the maps around it (lib/osr_maps.glsl
// gatherMaps: screen distance, normal agreement, plane distance), integrated against its BSDF:
//  - the diffuse lobe in closed form: reflectance / pi x the interpolated irradiance;
//  - GGX reflection lobes wider than a texel (alpha >= kNarrowLobeAlpha): `glossySamples` directions
//    drawn from the lobe by visible normals, the interpolated map radiance looked up there
//    (directions no gathered map's hemisphere contains count 0: osr_residual traces them);
//  - narrower lobes, transmission (glass and diffuse), clearcoat and sheen: left to
//    osr_residual, which path-traces them in full.
// Pixels no map covers get 0 here; osr_residual gives them the path tracer's answer instead.
// Adds passWeight x estimate to AccumPixel.indirect (w: sum of pass weights), and on a pass
// that traced its maps its luminance's moments to AccumPixel.compositeSq (the resolve's
// variance).
// In: GBufferPixel, MapPoint, MapProjection, clean maps. Out: AccumPixel.indirect, .compositeSq.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { CompositePush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  GBufferPixel g = gGBuffer[local];
  vec3 estimate = vec3(0.0);
  if (g.position.w > 0.5) {
    ShadingPoint sp = gbufferShadingPoint(g);
    MapGather gather = gatherMaps(gPush.grid, gPush.cleanMapOffset,
                                  uvec2(pixel % gFrame.width, pixel / gFrame.width), sp.position, sp.ns);
    if (gather.total > 0.0) {
      estimate = bsdfDiffuseReflectance(sp.bsdf, sp.woLocal) * kInvPi * gatherIrradiance(gather, sp.ns);
      if (ggxAlpha(sp.bsdf) >= kNarrowLobeAlpha && gPush.glossySamples > 0u) {
        Rng rng = pixelRng(gPush.pass, pixel, kSaltComposite);
        vec3 spec = vec3(0.0);
        for (uint i = 0u; i < gPush.glossySamples; ++i) {
          float pdf;
          vec3 wi = bsdfSampleReflection(sp.bsdf, sp.woLocal, rngNext2(rng), pdf);
          if (pdf <= 0.0) continue;
          vec3 f = bsdfEvalGlossy(sp.bsdf, sp.woLocal, wi);
          vec3 dir = toWorld(wi, sp.t, sp.b, sp.ns);
          if (dot(dir, sp.ng) <= 0.0) continue;
          // A direction no gathered map contains counts 0 here; the residual traces it in full.
          spec += max(f, vec3(0.0)) * gatherRadiance(gather, dir).rgb / pdf;
        }
        estimate += spec / float(gPush.glossySamples);
      }
      estimate *= g.throughput.rgb;
    }
  }
  AccumPixel a = gAccum[local];
  if (finite3(estimate)) {
    a.indirect.rgb += gPush.passWeight * estimate;
    a.compositeSq += weightedMoments(luminance(estimate), gPush.momentWeight);
  }
  a.indirect.w += gPush.passWeight;
  gAccum[local] = a;
}
