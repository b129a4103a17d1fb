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

// The BSDF's inputs at `surf` seen from the side `front` says, in the local frame (t, b, n).
BsdfParams bsdfParams(SurfaceSample surf, bool front, vec3 t, vec3 b, vec3 n) {
  SurfaceMaterial m = surf.m;
  BsdfParams p;
  p.baseColor = m.baseColor;
  p.metallic = m.metallic;
  p.specularColor = m.specularColor;
  p.roughness = m.roughness;
  p.specular = m.specular;
  p.eta = front ? m.ior : 1.0 / m.ior;
  p.transmission = m.transmission;
  p._pad0 = 0.0;
  p.clearcoatNormal = vec3(0.0, 0.0, 1.0);
  p.clearcoat = 0.0;
  p.sheenColor = vec3(0.0);
  p.sheenRoughness = 0.0;
  p.diffuseTransmissionColor = vec3(1.0);
  p.diffuseTransmission = 0.0;
  p.anisotropyDirection = vec2(1.0, 0.0);
  p.anisotropy = 0.0;
  p.clearcoatRoughness = 0.0;
  p.iridescence = 0.0;
  p.iridescenceIor = 1.3;
  p.iridescenceThickness = 0.0;
  p._pad1 = 0.0;
  if (sceneHas(kSceneFeatureLayers)) {
    // The coat is on the outside of the surface only (a coat seen from inside glass is not
    // the layer the file describes).
    p.clearcoat = front || m.doubleSided ? m.clearcoat : 0.0;
    p.clearcoatRoughness = m.clearcoatRoughness;
    if (p.clearcoat > 0.0) {
      vec3 nc = surf.clearcoatNormal;
      if (dot(nc, n) < 0.0) nc = -nc;  // the coat's normal on wo's side, as n is
      vec3 l = toLocal(nc, t, b, n);
      p.clearcoatNormal = l.z > 1e-4 ? normalize(l) : vec3(0.0, 0.0, 1.0);
    }
    p.sheenColor = m.sheenColor;
    p.sheenRoughness = m.sheenRoughness;
    p.diffuseTransmissionColor = m.diffuseTransmissionColor;
    p.diffuseTransmission = m.diffuseTransmission;
    p.anisotropy = m.anisotropy;
    if (m.anisotropy > 0.0) {
      vec2 d = toLocal(surf.anisotropyTangent, t, b, n).xy;
      float l = length(d);
      p.anisotropyDirection = l > 1e-6 ? d / l : vec2(1.0, 0.0);
      if (!(l > 1e-6)) p.anisotropy = 0.0;  // no tangent (degenerate uvs): isotropic
    }
    // The film lies on the outside, like the coat.
    p.iridescence = front || m.doubleSided ? m.iridescence : 0.0;
    p.iridescenceIor = m.iridescenceIor;
    p.iridescenceThickness = m.iridescenceThickness;
  }
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
  sp.bsdf = bsdfParams(surf, sp.front, sp.t, sp.b, sp.ns);
  return sp;
}

// Beer-Lambert transmittance of the segment of length `t` that ended at `surf` seen from its
// back side, i.e. travelled inside a closed mesh with KHR_materials_volume absorption (a camera
// or light inside such a mesh is not modelled). 1 everywhere else.
vec3 mediumTransmittance(SurfaceSample surf, bool front, float t) {
  if (!sceneHas(kSceneFeatureLayers) || front) return vec3(1.0);
  return exp(-surf.m.absorption * t);
}

// Ray origin leaving `sp` towards `dir`, offset to the side `dir` is on.
vec3 shadingRayOrigin(ShadingPoint sp, vec3 dir) {
  return offsetRayOrigin(sp.position, dot(dir, sp.ng) > 0.0 ? sp.ng : -sp.ng);
}

#endif
