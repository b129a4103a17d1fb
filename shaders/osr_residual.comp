#version 460
// osr_residual: what makes OSR converge. At each pixel's G-buffer surface x, `pathsPerPixel`
// directions wi drawn from the full BSDF (or, with guideShare > 0 on diffuse surfaces, from its
// mixture with the maps around the pixel: sampleGuided), each followed by a path-traced estimate
// L_pt of the light arriving after at least one bounce (lib/path.glsl). With g(wi) = rho_d / pi cos
// L_sh(wi) + [wide lobe] f_rest(wi) L^(wi) the function whose integral osr_composite computed
// (L_sh: the maps' SH radiance, lib/osr_maps.glsl gatherShRadiance, whose cosine integral is the
// composite's closed-form irradiance exactly; L^: the interpolated texel lookups the composite
// samples for glossy lobes), the residual (f L_pt - g) / pdf is an unbiased estimate of the
// composite's error (a control variate; two-level Monte Carlo, Dereviannykh et al. 2024), so
// composite + residual converges to the path tracer's answer. Lobes the composite left out (narrow,
// transmission, delta, clearcoat, sheen, diffuse transmission), glossy directions no gathered map
// contains and pixels no map covers have g = 0: their f L_pt / pdf is the path tracer's own answer,
// added to AccumPixel.indirect in full; the control-variate part goes to AccumPixel.residual, which
// the resolve blends in.
// In: GBufferPixel, MapPoint, clean maps, scene, BVH. Out: AccumPixel.indirect, .residual, .tracedSq.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { ResidualPush gPush; };

// A path's first direction from the mixture (1 - guide) x BSDF + guide x the gathered maps
// (lib/osr_maps.glsl sampleGatheredMaps: where the indirect light comes from), as a
// BsdfSample whose pdf is the mixture's and weight f cos / pdf: one-sample MIS with the
// balance heuristic, so the residual stays unbiased whatever the maps hold. Only where the
// BSDF has no glass or diffuse transmission (guide > 0), so no delta lobe and no direction
// below the surface carries light. False: no direction (a zero sample).
bool sampleGuided(ShadingPoint sp, MapGather gather, float guide, vec3 u, vec2 uExtra,
                  out BsdfSample s) {
  float pdfBsdf;
  vec3 fcos;
  if (u.x < guide) {
    vec3 dir;
    s.delta = false;
    if (!sampleGatheredMaps(gather, vec2(u.x / guide, u.y), vec2(u.z, uExtra.x), dir)) return false;
    s.wi = toLocal(dir, sp.t, sp.b, sp.ns);
    if (s.wi.z <= 0.0) return false;  // below the shading surface: f = 0 and no control variate
    fcos = bsdfEval(sp.bsdf, sp.woLocal, s.wi, pdfBsdf);
  } else {
    if (!bsdfSample(sp.bsdf, sp.woLocal, vec3((u.x - guide) / (1.0 - guide), u.y, u.z), s))
      return false;
    pdfBsdf = s.pdf;
    fcos = s.weight * s.pdf;
  }
  float pdf = guide * gatheredMapsPdf(gather, toWorld(s.wi, sp.t, sp.b, sp.ns)) +
              (1.0 - guide) * pdfBsdf;
  if (!(pdf > 0.0)) return false;
  s.pdf = pdf;
  s.weight = fcos / pdf;
  return true;
}

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
    float guide = 0.0;
    if (covered && gPush.guideShare > 0.0) {
      BsdfLobes lobes = bsdfLobeProbabilities(sp.bsdf, sp.woLocal);
      if (lobes.glass == 0.0 && lobes.diffuseSplit == 0.0) guide = gPush.guideShare * lobes.diffuse;
    }
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
        vec3 u = rngNext3(rng);
        bool sampled = guide > 0.0 ? sampleGuided(sp, gather, guide, u, rngNext2(rng), bs)
                                   : bsdfSample(sp.bsdf, sp.woLocal, u, bs);
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
      bool ended = pathBounce(p, uLight, uBsdf, uRoulette, false, r);
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
