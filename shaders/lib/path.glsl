// One bounce of a unidirectional path tracer with next-event estimation and MIS (power
// heuristic), shared by the path tracer (pt_trace), OSR's hemisphere maps (osr_maps) and its
// residual paths (osr_residual), so every estimate of indirect light is the same estimator.
// Russian roulette from the fourth surface on, survival min(sqrt(max(throughput)), 0.95), as
// Cycles' but capped (min(max, 0.95) ended long interreflection paths too early and was the
// noise: docs/pathtracer.md, "Against Cycles"); no fixed depth cap. Requires lib/scene.glsl,
// lib/bvh_traverse.glsl, lib/rng.glsl, lib/sampling.glsl, lib/bsdf.glsl, lib/ray_offset.glsl,
// lib/lights.glsl and lib/shading.glsl.
#ifndef OSR_LIB_PATH_GLSL
#define OSR_LIB_PATH_GLSL

// The state of one path between bounces.
struct PathState {
  vec3 origin;
  vec3 dir;
  vec3 beta;      // throughput
  float prevPdf;  // BSDF pdf of the direction that led here (0: camera ray or delta lobe)
  vec3 prevPos;
  uint bounce;    // surfaces met so far
};

PathState pathStart(vec3 origin, vec3 dir, vec3 beta, float prevPdf, vec3 prevPos, uint bounce) {
  PathState p;
  p.origin = origin;
  p.dir = dir;
  p.beta = beta;
  p.prevPdf = prevPdf;
  p.prevPos = prevPos;
  p.bounce = bounce;
  return p;
}

// What one bounce found: light leaving the surface met (emission, MIS-weighted against the
// previous BSDF sample) arriving after p.bounce interactions, light from next-event estimation
// arriving after p.bounce + 1, and the surface (for first-hit records).
struct BounceResult {
  vec3 emitted;
  vec3 nee;
  bool hit;
  vec3 position;
  vec3 normal;  // shading normal facing the ray (AOV convention); zero on a miss
  vec3 albedo;  // the denoisers' albedo guide at the hit (lib/bsdf.glsl denoiseAlbedo), where asked
  // A mirror (lib/bsdf.glsl bsdfGuideMirror): the denoisers' guides look into it (pt_trace's
  // first-hit record).
  bool mirror;
  bool nearSpecular;  // lib/bsdf.glsl bsdfNearSpecular: pt_trace's direct/indirect split
};

// Environment light seen along a ray that left the scene.
vec3 missRadiance(PathState p) {
  if (!sceneHas(kSceneFeatureEnvironment) || gSceneInfo.envWidth == 0u) return vec3(0.0);
  float w = p.prevPdf > 0.0 ? powerHeuristic(p.prevPdf, environmentLightPdf(p.dir)) : 1.0;
  return p.beta * w * environmentRadiance(p.dir);
}

// Emission of the surface hit at `surf`, weighted by MIS against light sampling when the ray
// was BSDF-sampled (p.prevPdf > 0).
vec3 hitEmission(PathState p, uint triangle, SurfaceSample surf, ShadingPoint sp) {
  if (!(sp.front || surf.m.doubleSided) || !any(greaterThan(surf.m.emission, vec3(0.0))))
    return vec3(0.0);
  float w = 1.0;
  if (p.prevPdf > 0.0)
    w = powerHeuristic(p.prevPdf, emissivePdf(triangle, p.prevPos, surf.position, sp.ng));
  return p.beta * w * surf.m.emission;
}

// Next-event estimation at `sp` (light arriving there in one hop, times f * cos / pdf), MIS
// against BSDF sampling. u: three uniform numbers. Not multiplied by the path throughput.
vec3 estimateDirect(ShadingPoint sp, vec3 u) {
  LightSample ls;
  if (!sampleLight(sp.position, u, ls)) return vec3(0.0);
  vec3 wiLocal = toLocal(ls.wi, sp.t, sp.b, sp.ns);
  // Reject directions on different sides by the shading and geometric normals (light leaks
  // through shading-normal interpolation).
  if ((dot(ls.wi, sp.ng) > 0.0) != (wiLocal.z > 0.0)) return vec3(0.0);
  float bsdfPdf;
  vec3 f = bsdfEval(sp.bsdf, sp.woLocal, wiLocal, bsdfPdf);
  if (!any(greaterThan(f, vec3(0.0)))) return vec3(0.0);
  float tMax = ls.distance == kInfinity ? kInfinity : ls.distance * (1.0 - 1e-4);
  if (bvhAnyHit(shadingRayOrigin(sp, ls.wi), ls.wi, 0.0, tMax)) return vec3(0.0);
  float w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, bsdfPdf);
  return f * ls.radiance * (w / ls.pdf);
}

// Samples the BSDF at `sp` and turns `p` into the continuation ray (throughput, pdf, Russian
// roulette). Returns true when the path has ended.
bool pathContinue(inout PathState p, ShadingPoint sp, vec3 uBsdf, float uRoulette) {
  BsdfSample bs;
  if (!bsdfSample(sp.bsdf, sp.woLocal, uBsdf, bs)) return true;
  vec3 wi = toWorld(bs.wi, sp.t, sp.b, sp.ns);
  if ((dot(wi, sp.ng) > 0.0) != (bs.wi.z > 0.0)) return true;
  p.beta *= bs.weight;
  p.prevPdf = bs.delta ? 0.0 : bs.pdf;
  p.prevPos = sp.position;
  p.origin = shadingRayOrigin(sp, wi);
  p.dir = wi;
  if (p.bounce >= 3u) {
    // Capped below 1 so that a closed scene of albedo 1 (no depth cap here) still ends.
    float survive = min(sqrt(maxComponent(p.beta)), 0.95);
    if (uRoulette >= survive) return true;
    p.beta /= survive;
  }
  p.bounce += 1u;
  return !(maxComponent(p.beta) > 0.0);
}

// One bounce: finds the next surface, its emission and next-event estimate, samples the BSDF
// for the continuation. uLight, uBsdf: three uniform numbers each. recordAlbedo: fill r.albedo
// too (only the path tracer's first-hit record reads it). Returns true when the path has ended.
bool pathBounce(inout PathState p, vec3 uLight, vec3 uBsdf, float uRoulette, bool recordAlbedo,
                out BounceResult r) {
  r.emitted = vec3(0.0);
  r.nee = vec3(0.0);
  r.hit = false;
  r.position = vec3(0.0);
  r.normal = vec3(0.0);
  r.albedo = vec3(0.0);
  r.mirror = false;
  r.nearSpecular = false;
  Hit hit;
  if (!bvhClosestHit(p.origin, p.dir, 0.0, kInfinity, hit)) {
    r.emitted = missRadiance(p);
    return true;
  }
  SurfaceSample surf = surfaceAt(hit.triangle, hit.barycentrics);
  ShadingPoint sp = shadingPoint(surf, -p.dir);
  p.beta *= mediumTransmittance(surf, sp.front, hit.t);
  r.hit = true;
  r.position = surf.position;
  r.normal = facingShadingNormal(surf, -p.dir);
  if (recordAlbedo) r.albedo = denoiseAlbedo(sp.bsdf, sp.woLocal);
  r.mirror = bsdfGuideMirror(sp.bsdf);
  r.nearSpecular = bsdfNearSpecular(sp.bsdf);
  r.emitted = hitEmission(p, hit.triangle, surf, sp);
  r.nee = p.beta * estimateDirect(sp, uLight);
  return pathContinue(p, sp, uBsdf, uRoulette);
}

#endif
