#version 460
// osr_gbuffer: the first surface through each pixel that is not near-specular, for this
// pass's sub-pixel jitter (antialiasing comes from averaging passes). Mirror-like metals and
// smooth glass (lib/bsdf.glsl bsdfNearSpecular) are followed by sampling their BSDF, with
// the chain's throughput kept; emission met on the way (the camera's own view of lights, and
// lights seen in mirrors) goes straight to the direct layer, the latter's moments to
// AccumPixel.mirroredSq (the resolve's variance). The lights seen directly are
// averaged over `cameraRays` camera rays of the pixel filter (the first is the G-buffer's own):
// a light's edge pixels would otherwise be speckled for as many passes as they take to average.
// The first-hit record (the denoisers' guides) follows the chain through mirrors only, as path
// tracing's does (lib/first_hit.glsl): the maps sit on what glass shows, the guides on the glass.
// Unlike path tracing's, light met past a mirror is not light seen: the chain's sampled
// direction makes it noise, which the variance holds (AccumPixel.mirroredSq), and a pixel of
// light seen is kept as it is (room's mirror kept a firefly of relMSE 11 through the network).
// In: CameraFrame, scene, BVH. Out: GBufferPixel, AccumPixel first-hit records and emission.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/first_hit.glsl"  // lightSeen

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { GBufferPush gPush; };

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= gPush.pixelCount) return;
  uint pixel = gPush.pixelOffset + local;
  Rng rng = pixelRng(gPush.pass, pixel, kSaltGBuffer);
  vec3 origin, dir;
  cameraRay(gFrame, pixel % gFrame.width, pixel / gFrame.width, rngNext2(rng), origin, dir);

  GBufferPixel g;
  g.position = vec4(0.0);
  g.normal = vec4(0.0, 0.0, 1.0, 0.0);
  g.geomNormal = vec4(0.0, 0.0, 1.0, 1.0);
  g.wo = vec4(-dir, 0.0);
  g.throughput = vec4(0.0);
  g.bsdf = bsdfBlack();
  AccumPixel a = gAccum[local];
  vec3 beta = vec3(1.0);
  vec3 emitted = vec3(0.0);
  vec3 mirrored = vec3(0.0);  // the part met past a near-specular bounce (chain >= 1)
  // Each camera ray's share of the lights seen directly (first hit); later hits count whole.
  const float cameraShare = 1.0 / float(max(gPush.cameraRays, 1u));
  float rayLength = 0.0;
  FirstHit first = noFirstHit();
  GuideChain guide = guideChainStart();
  for (uint chain = 0u; chain <= kMaxSpecularChain; ++chain) {
    Hit hit;
    if (!bvhClosestHit(origin, dir, 0.0, kInfinity, hit)) {
      // Delta-like bounces only so far: the environment is seen at full weight.
      vec3 env = missRadiance(pathStart(origin, dir, beta, 0.0, origin, chain));
      emitted += (chain == 0u ? cameraShare : 1.0) * env;
      if (chain > 0u) mirrored += env;
      if (chain == 0u) first.light = lightSeen(env);
      break;
    }
    SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
    ShadingPoint sp = shadingPoint(surf, -dir);
    rayLength += hit.t;
    beta *= mediumTransmittance(surf, sp.front, hit.t);
    vec3 emission = hitEmission(pathStart(origin, dir, beta, 0.0, origin, chain), hit.triangle, surf, sp);
    emitted += (chain == 0u ? cameraShare : 1.0) * emission;
    if (chain > 0u) mirrored += emission;
    if (chain == 0u) first.light = lightSeen(emission);
    if (guide.open) {
      guideChainRecord(guide, first, chain, hit.t, cameraDepth(gFrame, surf.position),
                       denoiseAlbedo(sp.bsdf, sp.woLocal), facingShadingNormal(surf, -dir),
                       bsdfGuideMirror(sp.bsdf));
    }
    if (!bsdfNearSpecular(sp.bsdf)) {
      g.position = vec4(sp.position, 1.0);
      g.normal = vec4(sp.ns, 0.0);
      g.geomNormal = vec4(sp.ng, sp.front ? 1.0 : 0.0);
      g.wo = vec4(sp.wo, rayLength);
      g.throughput = vec4(beta, 0.0);
      g.bsdf = sp.bsdf;
      break;
    }
    BsdfSample bs;
    if (chain == kMaxSpecularChain || !bsdfSample(sp.bsdf, sp.woLocal, rngNext3(rng), bs)) break;
    vec3 wi = toWorld(bs.wi, sp.t, sp.b, sp.ns);
    if ((dot(wi, sp.ng) > 0.0) != (bs.wi.z > 0.0)) break;
    beta *= bs.weight;
    origin = shadingRayOrigin(sp, wi);
    dir = wi;
  }
  a.albedo += vec4(first.albedo, 1.0);  // w: passes, for the first-hit layers' average
  a.normal.rgb += first.normal;
  a.depth += first.hit ? vec4(first.depth, 1.0, 0.0, 0.0) : vec4(0.0);
  a.depth.z += cameraShare * first.light;
  // The other camera rays: the emission (or environment) of their first hit only.
  for (uint s = 1u; s < gPush.cameraRays; ++s) {
    vec3 o, d;
    cameraRay(gFrame, pixel % gFrame.width, pixel / gFrame.width, rngNext2(rng), o, d);
    Hit hit;
    PathState start = pathStart(o, d, vec3(1.0), 0.0, o, 0u);
    vec3 e;
    if (bvhClosestHit(o, d, 0.0, kInfinity, hit)) {
      SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
      e = hitEmission(start, hit.triangle, surf, shadingPoint(surf, -d));
    } else {
      e = missRadiance(start);
    }
    emitted += cameraShare * e;
    a.depth.z += cameraShare * lightSeen(e);
  }
  if (finite3(emitted)) {
    a.direct.rgb += gPush.directWeight * emitted;  // as osr_direct weighs it
    // The chain's sampled directions make what it meets noise: the denoisers' variance holds
    // it (a lamp met once in a mirror's GGX tail was a firefly they kept).
    a.mirroredSq += weightedMoments(luminance(mirrored), gPush.directWeight);
  }
  gGBuffer[local] = g;
  gAccum[local] = a;
}
