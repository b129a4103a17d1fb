#version 460
// osr_residual: what makes OSR converge. At each pixel's G-buffer surface x, `pathsPerPixel`
// directions wi drawn from the full BSDF, each followed by a path-traced estimate L_pt of the
// light arriving after at least one bounce (lib/path.glsl). With g(wi) = rho_d / pi cos
// L_sh(wi) + [wide lobe] f_rest(wi) L^(wi) the function whose integral osr_composite computed
// (L_sh: the maps' SH radiance, lib/osr_maps.glsl gatherShRadiance, whose cosine integral is
// the composite's closed-form irradiance exactly; L^: the interpolated texel lookups the
// composite samples for glossy lobes), the residual (f L_pt - g) / pdf is an unbiased
// estimate of the composite's error (a control variate; two-level Monte Carlo, Dereviannykh
// et al. 2024), so composite + residual converges to the path tracer's answer.
// Lobes the composite left out (narrow, transmission, delta, clearcoat, sheen, diffuse
// transmission), glossy directions no gathered map contains and pixels no map covers have
// g = 0: their f L_pt / pdf is the path tracer's own answer, added to AccumPixel.indirect in
// full; the control-variate part goes to AccumPixel.residual, which the resolve blends in.
// In: GBufferPixel, MapPoint, clean maps, scene, BVH. Out: AccumPixel.indirect, .residual, .tracedSq.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { ResidualPush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  GBufferPixel g = gGBuffer[local];
  vec3 always = vec3(0.0), blended = vec3(0.0);
  if (g.position.w > 0.5) {
    ShadingPoint sp = gbufferShadingPoint(g);
    MapGather gather = gatherMaps(gPush.grid, gPush.cleanMapOffset,
                                  uvec2(pixel % gFrame.width, pixel / gFrame.width), sp.position, sp.ns);
    bool covered = gather.total > 0.0;
    bool wide = ggxAlpha(sp.bsdf) >= kNarrowLobeAlpha;
    vec3 rho = bsdfDiffuseReflectance(sp.bsdf, sp.woLocal);
    vec3 shWeights[9];
    if (covered) gatherShWeights(gather, sp.ns, shWeights);
    Rng rng = pixelRng(gPush.pass, pixel, kSaltResidual);
    // One flat loop over the bounces of successive paths (see osr_maps.comp for why).
    uint i = 0u;
    bool live = false;
    PathState p;
    BsdfSample bs;
    vec3 lpt = vec3(0.0);
    while (i < gPush.pathsPerPixel) {
      if (!live) {
        lpt = vec3(0.0);
        vec3 wi = vec3(0.0);
        bool sampled = bsdfSample(sp.bsdf, sp.woLocal, rngNext3(rng), bs);
        bool ok = sampled;
        if (ok) {
          wi = toWorld(bs.wi, sp.t, sp.b, sp.ns);
          ok = (dot(wi, sp.ng) > 0.0) == (bs.wi.z > 0.0);
        }
        if (!ok) {
          // Below the geometric surface no light arrives (as in the path tracer), but the
          // composite's closed form integrates the diffuse control variate over the whole
          // shading hemisphere: it is subtracted here too.
          if (sampled && covered && !bs.delta && bs.wi.z > 0.0)
            blended -= rho * kInvPi * bs.wi.z * gatherShRadiance(gather, shWeights, wi) / bs.pdf;
          i += 1u;
          continue;
        }
        p = pathStart(shadingRayOrigin(sp, wi), wi, vec3(1.0), bs.delta ? 0.0 : bs.pdf,
                      sp.position, 1u);
        live = true;
      }
      uint bounce = p.bounce;
      vec3 uLight = rngNext3(rng);
      vec3 uBsdf = rngNext3(rng);
      float uRoulette = rngNext(rng);
      BounceResult r;
      bool ended = pathBounce(p, uLight, uBsdf, uRoulette, r);
      if (bounce != 1u) lpt += r.emitted;
      lpt += r.nee;
      if (!ended) continue;
      live = false;
      i += 1u;
      if (!finite3(lpt)) continue;
      if (bs.delta || !covered) {
        always += bs.weight * lpt;
        continue;
      }
      // Split f cos into the diffuse lobe, the glossy lobes the composite took from the maps
      // (wide ones only) and the rest (f cos = weight * pdf).
      // A glossy direction no gathered map contains is the composite's 0: traced in full.
      vec3 fcos = bs.weight * bs.pdf;
      vec3 fd = bsdfEvalDiffuse(sp.bsdf, sp.woLocal, bs.wi);
      vec3 dir = toWorld(bs.wi, sp.t, sp.b, sp.ns);
      vec4 lMaps = wide ? gatherRadiance(gather, dir) : vec4(0.0);
      vec3 fGlossy = lMaps.w > 0.0 ? bsdfEvalGlossy(sp.bsdf, sp.woLocal, bs.wi) : vec3(0.0);
      vec3 fRest = max(fcos - fd - fGlossy, vec3(0.0));
      vec3 cv = rho * kInvPi * max(bs.wi.z, 0.0) * gatherShRadiance(gather, shWeights, dir);
      cv += fGlossy * lMaps.rgb;
      blended += ((fd + fGlossy) * lpt - cv) / bs.pdf;
      always += fRest * lpt / bs.pdf;
    }
    float inv = 1.0 / float(max(gPush.pathsPerPixel, 1u));
    always *= g.throughput.rgb * inv;
    blended *= g.throughput.rgb * inv;
  }
  AccumPixel a = gAccum[local];
  if (finite3(always) && finite3(blended)) {
    a.indirect.rgb += gPush.passWeight * always;
    a.tracedSq += weightedMoments(luminance(always), gPush.passWeight);
    a.residual.rgb += gPush.passWeight * blended;
    // Second moments, so the resolve knows the residual's noise (shared/osr.h).
    a.residualSq += vec4(gPush.passWeight * blended * blended, gPush.passWeight * gPush.passWeight);
  }
  a.residual.w += float(gPush.pathsPerPixel);
  gAccum[local] = a;
}
