// A surface hit made ready for shading: normals facing the incoming ray, the local frame and
// the BSDF parameters. Shared by the path tracer and every OSR pass, so they all shade alike.
// Requires lib/scene.glsl, lib/sampling.glsl and lib/bsdf.glsl included before.
#ifndef OSR_LIB_SHADING_GLSL
#define OSR_LIB_SHADING_GLSL

struct ShadingPoint {
  vec3 position;
  vec3 ng;    // geometric normal, on wo's side
  vec3 ns;    // shading normal, on wo's side; the geometric one where it puts wo below
  vec3 t, b;  // frameFromNormal(ns)
  vec3 wo;    // towards the previous vertex (world)
  vec3 woLocal;
  bool front;  // wo is on the side the winding faces
  BsdfParams bsdf;
};

BsdfParams bsdfParams(SurfaceMaterial m, bool front) {
  BsdfParams p;
  p.baseColor = m.baseColor;
  p.metallic = m.metallic;
  p.specularColor = m.specularColor;
  p.roughness = m.roughness;
  p.specular = m.specular;
  p.eta = front ? m.ior : 1.0 / m.ior;
  p.transmission = m.transmission;
  p._pad0 = 0.0;
  return p;
}

// The shading normal as the AOV records it: flipped to the geometric side wo sees, before the
// below-horizon fallback (the film's normal layer).
vec3 facingShadingNormal(SurfaceSample surf, vec3 wo) {
  vec3 ns = surf.shadingNormal;
  if (dot(ns, surf.geometricNormal) < 0.0) ns = -ns;  // vertex normals against the winding
  return dot(surf.geometricNormal, wo) > 0.0 ? ns : -ns;
}

ShadingPoint shadingPoint(SurfaceSample surf, vec3 wo) {
  ShadingPoint sp;
  sp.position = surf.position;
  sp.wo = wo;
  sp.front = dot(surf.geometricNormal, wo) > 0.0;
  sp.ng = sp.front ? surf.geometricNormal : -surf.geometricNormal;
  sp.ns = facingShadingNormal(surf, wo);
  // Where the shading normal puts wo below the horizon, use the geometric normal rather than
  // shade a direction the BSDF has no value for.
  if (dot(sp.ns, wo) <= 1e-4) sp.ns = sp.ng;
  frameFromNormal(sp.ns, sp.t, sp.b);
  sp.woLocal = toLocal(wo, sp.t, sp.b, sp.ns);
  sp.bsdf = bsdfParams(surf.m, sp.front);
  return sp;
}

// Ray origin leaving `sp` towards `dir`, offset to the side `dir` is on.
vec3 shadingRayOrigin(ShadingPoint sp, vec3 dir) {
  return offsetRayOrigin(sp.position, dot(dir, sp.ng) > 0.0 ? sp.ng : -sp.ng);
}

#endif
