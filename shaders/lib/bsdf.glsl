// The glTF 2.0 metallic-roughness BSDF with KHR_materials_specular, _ior and _transmission,
// and the layered lobes of KHR_materials_clearcoat, _sheen, _diffuse_transmission and
// _anisotropy, in the local frame (z = shading normal, wo.z > 0: the caller flips the frame
// for back-side hits and sets eta accordingly).
//   f = coat(sheen(base))
//   base       = metallic * metal + (1 - metallic) * ((1 - t) * dielectric + t * glass)
//   metal      = F_schlick(baseColor, 1) * D G / (4 |wo.z| |wi.z|)              (glTF spec)
//   dielectric = (1 - specular * max(F)) * diffuse + specular * F * D G / (4 ...)
//                F = F0 + (F90 - F0)(1 - v.h)^5, F0 = min(((ior-1)/(ior+1))^2 specularColor, 1)
//   diffuse    = (1 - dt) baseColor / pi above, dt * diffuseTransmissionColor / pi below
//                (KHR_materials_diffuse_transmission; below, the Fresnel weight is taken at wo)
//   glass      = rough dielectric BTDF/BRDF with exact Fresnel (Walter et al. 2007), or a
//                delta reflect/refract pair when alpha < kDeltaAlpha; refraction tinted by
//                baseColor. No 1/eta^2 radiance scaling (it cancels for a camera outside).
//   sheen(x)   = sheenColor * D_charlie V_charlie + x * min(1 - max(sheenColor) E(wo.z),
//                1 - max(sheenColor) E(|wi.z|))     (KHR_materials_sheen, albedo scaling)
//   coat(x)    = x * (1 - c Fc(wo.nc)) + c Fc(wo.hc) D G / (4 |wo.nc| |wi.nc|)
//                Fc: Schlick with F0 = 0.04, nc the coat's own normal (KHR_materials_clearcoat)
// KHR_materials_iridescence: every Fresnel of the base layer (metal, dielectric, the glass
// interface entered from outside) becomes mix(F(v.h), F_film(wo.z), iridescence), F_film the
// thin film over a base of that F0 (shared/thin_film.h, clamped to [0, 1]) at the outgoing
// direction, as the Khronos sample renderer has it; the diffuse weight 1 - specular * max(F)
// and glass's refraction 1 - F follow it. The film sees air above it, also under a coat (the
// extension would take the coat's ior).
// D: GGX (Trowbridge-Reitz), anisotropic with alpha_t = mix(alpha, 1, strength^2) along the
// anisotropy direction (KHR_materials_anisotropy); G: height-correlated Smith (Heitz 2014);
// the GGX lobes are sampled by visible normals (Heitz 2018), sheen by the cosine. F90 of the
// dielectric layer is specular * saturate(50 * max(F0)) (Filament's rule): a zero specular
// colour means "no specular at all", which is what Blender's exporter writes for a Lambertian
// Diffuse BSDF.
// bsdfEval returns f * |cos(wi)| and the solid-angle pdf of bsdfSample's continuous part.
#ifndef OSR_LIB_BSDF_GLSL
#define OSR_LIB_BSDF_GLSL
#include "lib/sampling.glsl"
#include "lib/sheen_albedo.glsl"
#include "shared/thin_film.h"

// False where the includer knows no material transmits (pt_trace: kSceneFeatureTransmission):
// the glass lobe's code is then compiled out (on lavapipe a divergent branch costs all lanes).
#ifndef OSR_BSDF_TRANSMISSION
#define OSR_BSDF_TRANSMISSION true
#endif
// False where the includer knows no material has a layered lobe (kSceneFeatureLayers): the
// clearcoat, sheen, diffuse transmission, anisotropy and iridescence code is compiled out.
#ifndef OSR_BSDF_LAYERS
#define OSR_BSDF_LAYERS true
#endif

const float kMinAlpha = 1e-3;
const float kDeltaAlpha = 1e-3;  // glass smoother than this is a perfect interface
const float kMinSheenRoughness = 0.07;
const float kCoatF0 = 0.04;      // ior 1.5

struct BsdfSample {
  vec3 wi;
  vec3 weight;  // f * |cos| / pdf (delta lobes: the lobe's weight)
  float pdf;    // solid-angle pdf of the continuous part; 0 for delta samples
  bool delta;
};

// A material that reflects nothing (the G-buffer's "no surface").
BsdfParams bsdfBlack() {
  BsdfParams p;
  p.baseColor = vec3(0.0);
  p.metallic = 0.0;
  p.specularColor = vec3(0.0);
  p.roughness = 1.0;
  p.specular = 0.0;
  p.eta = 1.0;
  p.transmission = 0.0;
  p._pad0 = 0.0;
  p.clearcoatNormal = vec3(0.0, 0.0, 1.0);
  p.clearcoat = 0.0;
  p.sheenColor = vec3(0.0);
  p.sheenRoughness = 0.0;
  p.diffuseTransmissionColor = vec3(0.0);
  p.diffuseTransmission = 0.0;
  p.anisotropyDirection = vec2(1.0, 0.0);
  p.anisotropy = 0.0;
  p.clearcoatRoughness = 0.0;
  p.iridescence = 0.0;
  p.iridescenceIor = 1.3;
  p.iridescenceThickness = 0.0;
  p._pad1 = 0.0;
  return p;
}

float ggxAlpha(BsdfParams p) { return max(p.roughness * p.roughness, kMinAlpha); }
bool glassIsDelta(BsdfParams p) { return p.roughness * p.roughness < kDeltaAlpha; }

// Mirror-like metal (GGX alpha below kNearSpecularAlpha) and smooth glass: OSR's G-buffer
// follows them to the first surface that is not, and both integrators count light met on the
// way, and the light reaching that surface in one hop, in the direct layer.
const float kNearSpecularAlpha = 0.01;
bool bsdfNearSpecular(BsdfParams p) {
  bool mirror = p.metallic >= 0.999 && p.roughness * p.roughness < kNearSpecularAlpha;
  bool glass = OSR_BSDF_TRANSMISSION && p.transmission >= 0.999 && p.metallic <= 0.001 &&
               glassIsDelta(p);
  return mirror || glass;
}

// A mirror to the denoisers' guides: an isotropic metal of roughness below 0.1, whose
// reflection the first-hit record looks into (lib/first_hit.glsl), in path tracing and OSR.
const float kGuideMirrorRoughness = 0.1;
bool bsdfGuideMirror(BsdfParams p) {
  // Anisotropy widens the lobe along one axis.
  return p.roughness < kGuideMirrorRoughness && p.metallic >= 0.99 && p.anisotropy == 0.0;
}

// (alpha along local x, alpha along local y) of the base GGX lobes, in the frame bsdfAnisoFrame
// rotates into (x = the anisotropy direction).
vec2 ggxAlpha2(BsdfParams p) {
  float a = ggxAlpha(p);
  if (!OSR_BSDF_LAYERS || p.anisotropy <= 0.0) return vec2(a);
  float s = clamp(p.anisotropy, 0.0, 1.0);
  return vec2(mix(a, 1.0, s * s), a);
}

// Rotation about z taking the anisotropy direction to +x (identity without anisotropy). The
// isotropic lobes are unchanged by it; the coat's normal turns with the frame.
vec3 bsdfAnisoRotate(BsdfParams p, vec3 w) {
  vec2 d = p.anisotropyDirection;
  return vec3(d.x * w.x + d.y * w.y, -d.y * w.x + d.x * w.y, w.z);
}
vec3 bsdfAnisoUnrotate(BsdfParams p, vec3 w) {
  vec2 d = p.anisotropyDirection;
  return vec3(d.x * w.x - d.y * w.y, d.y * w.x + d.x * w.y, w.z);
}

float ggxD(vec3 h, vec2 a) {
  vec3 s = vec3(h.x / a.x, h.y / a.y, h.z);
  float d = dot(s, s);
  return 1.0 / (kPi * a.x * a.y * d * d);
}

float ggxLambda(vec3 w, vec2 a) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0) return 1e30;
  float t2 = (a.x * a.x * w.x * w.x + a.y * a.y * w.y * w.y) / c2;
  return 0.5 * (-1.0 + sqrt(1.0 + t2));
}

float ggxG1(vec3 w, vec2 a) { return 1.0 / (1.0 + ggxLambda(w, a)); }
float ggxG2(vec3 wo, vec3 wi, vec2 a) {
  return 1.0 / (1.0 + ggxLambda(wo, a) + ggxLambda(wi, a));
}

// Density of visible normals h seen from wo (wo.z > 0).
float ggxVisiblePdf(vec3 wo, vec3 h, vec2 a) {
  return ggxG1(wo, a) * max(0.0, dot(wo, h)) * ggxD(h, a) / wo.z;
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals".
vec3 ggxSampleVisible(vec3 wo, vec2 alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha.x * wo.x, alpha.y * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0 * kPi * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha.x * nh.x, alpha.y * nh.y, max(1e-7, nh.z)));
}

// Unpolarised Fresnel reflectance of a dielectric interface; eta = n_transmitted / n_incident.
float fresnelDielectric(float cosI, float eta) {
  cosI = clamp(cosI, 0.0, 1.0);
  float sin2T = (1.0 - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0) return 1.0;
  float cosT = sqrt(1.0 - sin2T);
  float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

float schlickWeight(float c) {
  float m = clamp(1.0 - c, 0.0, 1.0);
  float m2 = m * m;
  return m2 * m2 * m;
}

vec3 dielectricF0(BsdfParams p) {
  float r = (p.eta - 1.0) / (p.eta + 1.0);
  return min(vec3(r * r) * p.specularColor, vec3(1.0));
}

bool bsdfHasFilm(BsdfParams p) { return OSR_BSDF_LAYERS && p.iridescence > 0.0; }

// f, the Fresnel of a base of normal-incidence reflectance f0, mixed towards the thin film's
// by the iridescence factor. The film's is taken at wo (cosO = wo.z), as the Khronos sample
// renderer takes it at n.v: constant over wi, it keeps the layer's energy below 1 (a white
// dielectric reflects F_film times the GGX albedo plus 1 - F_film diffusely). At v.h instead,
// the film's peaks can sit under the specular lobe and miss the diffuse weight: a white
// furnace of 1.035 (roughness 0.5, wo at 70 degrees, film ior 2.2, 250 nm).
vec3 withFilm(BsdfParams p, vec3 f, vec3 f0, float cosO) {
  if (!bsdfHasFilm(p)) return f;
  vec3 film = thinFilmFresnel(1.0, p.iridescenceIor, p.iridescenceThickness, f0, cosO);
  return mix(f, film, clamp(p.iridescence, 0.0, 1.0));
}

// The dielectric's grazing reflectance: 1, or less for an f0 below 2 % (a specular colour near 0).
float dielectricF90(vec3 f0) { return clamp(50.0 * maxComponent(f0), 0.0, 1.0); }

// The dielectric's Fresnel at v.h for the outgoing direction of cosine cosO.
vec3 dielectricFresnel(BsdfParams p, float voh, float cosO) {
  vec3 f0 = dielectricF0(p);
  return withFilm(p, mix(f0, vec3(dielectricF90(f0)), schlickWeight(voh)), f0, cosO);
}

// The metal's Fresnel (glTF: Schlick from baseColor to 1).
vec3 metalFresnel(BsdfParams p, float voh, float cosO) {
  return withFilm(p, mix(p.baseColor, vec3(1.0), schlickWeight(voh)), p.baseColor, cosO);
}

// The glass interface's reflectance at v.h (exact, rgb with a film) and the probability of
// choosing reflection: the film's mean, so that without it both are the exact Fresnel. The
// film is on the outside only: from inside (eta < 1) the interface is bare.
vec3 glassFresnel(BsdfParams p, float voh, float cosO, out float reflectProbability) {
  float fr = fresnelDielectric(voh, p.eta);
  vec3 f = vec3(fr);
  if (bsdfHasFilm(p) && p.eta > 1.0) {
    float r = (p.eta - 1.0) / (p.eta + 1.0);
    f = withFilm(p, f, vec3(r * r), cosO);
  }
  reflectProbability = clamp((f.x + f.y + f.z) / 3.0, 0.0, 1.0);
  return f;
}

// ---- Layers ------------------------------------------------------------------------------

float coatFresnel(float c) { return mix(kCoatF0, 1.0, schlickWeight(c)); }
vec2 coatAlpha(BsdfParams p) { return vec2(max(p.clearcoatRoughness * p.clearcoatRoughness, kMinAlpha)); }
// The share of light the coat reflects at wo: what the layers below lose.
float coatWeight(BsdfParams p, vec3 wo) {
  if (!OSR_BSDF_LAYERS || p.clearcoat <= 0.0) return 0.0;
  return clamp(p.clearcoat, 0.0, 1.0) * coatFresnel(abs(dot(wo, p.clearcoatNormal)));
}

// An orthonormal frame around the coat's normal (local coordinates in, coat coordinates out).
vec3 toCoat(BsdfParams p, vec3 w) {
  vec3 n = p.clearcoatNormal;
  vec3 t, b;
  frameFromNormal(n, t, b);
  return vec3(dot(w, t), dot(w, b), dot(w, n));
}
vec3 fromCoat(BsdfParams p, vec3 w) {
  vec3 n = p.clearcoatNormal;
  vec3 t, b;
  frameFromNormal(n, t, b);
  return toWorld(w, t, b, n);
}

float sheenAlpha(BsdfParams p) {
  float r = max(p.sheenRoughness, kMinSheenRoughness);
  return r * r;
}

// Conty and Kulla 2017, as KHR_materials_sheen writes it.
float sheenL(float x, float a) {
  float o = (1.0 - a) * (1.0 - a);
  return mix(21.5473, 25.3245, o) / (1.0 + mix(3.82987, 3.32435, o) * pow(x, mix(0.19823, 0.16801, o))) +
         mix(-1.97760, -1.27393, o) * x + mix(-4.32054, -4.85967, o);
}
float sheenLambda(float c, float a) {
  c = abs(c);
  return c < 0.5 ? exp(sheenL(c, a)) : exp(2.0 * sheenL(0.5, a) - sheenL(1.0 - c, a));
}
// The sheen lobe's f (per unit sheenColor) for wo, wi above the surface.
float sheenBrdf(BsdfParams p, vec3 wo, vec3 wi) {
  float a = sheenAlpha(p);
  vec3 h = normalize(wo + wi);
  float sin2h = max(0.0, 1.0 - h.z * h.z);
  float d = (2.0 + 1.0 / a) * pow(sin2h, 0.5 / a) / (2.0 * kPi);
  float v = 1.0 / ((1.0 + sheenLambda(wo.z, a) + sheenLambda(wi.z, a)) * (4.0 * wo.z * wi.z));
  return d * v;
}
// What the sheen layer leaves to the layers below for the pair (wo, wi).
float sheenScaling(BsdfParams p, vec3 wo, vec3 wi) {
  float s = maxComponent(p.sheenColor);
  if (!OSR_BSDF_LAYERS || s <= 0.0) return 1.0;
  float r = p.sheenRoughness;
  return max(0.0, min(1.0 - s * sheenAlbedo(wo.z, r), 1.0 - s * sheenAlbedo(abs(wi.z), r)));
}

// ---- The mixture ---------------------------------------------------------------------------

// Lobe selection probabilities at wo. Zero everywhere for a black, non-transmissive material.
struct BsdfLobes {
  float reflection;  // base GGX reflection (metal + dielectric specular)
  float diffuse;     // Lambertian reflection and diffuse transmission (split by diffuseSplit)
  float glass;
  float coat;
  float sheen;
  float diffuseSplit;  // probability that a diffuse sample transmits
};

BsdfLobes bsdfLobeProbabilities(BsdfParams p, vec3 wo) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  vec3 fm = metalFresnel(p, wo.z, wo.z);
  float fd = p.specular * maxComponent(dielectricFresnel(p, wo.z, wo.z));
  BsdfLobes l;
  float dr = luminance(p.baseColor), dtw = 0.0;
  if (OSR_BSDF_LAYERS) {
    float dt = clamp(p.diffuseTransmission, 0.0, 1.0);
    dtw = dt * luminance(p.diffuseTransmissionColor);
    dr *= 1.0 - dt;
  }
  float under = 1.0 - coatWeight(p, wo);
  if (OSR_BSDF_LAYERS && maxComponent(p.sheenColor) > 0.0)
    under *= max(0.0, 1.0 - maxComponent(p.sheenColor) * sheenAlbedo(wo.z, p.sheenRoughness));
  l.reflection = under * (m * luminance(fm) + (1.0 - m) * (1.0 - t) * fd);
  l.diffuse = under * (1.0 - m) * (1.0 - t) * (1.0 - fd) * (dr + dtw);
  l.glass = under * (1.0 - m) * t;
  l.coat = coatWeight(p, wo);
  l.sheen = OSR_BSDF_LAYERS ? luminance(p.sheenColor) * min(sheenAlbedo(wo.z, p.sheenRoughness), 1.0) : 0.0;
  l.diffuseSplit = dr + dtw > 0.0 ? dtw / (dr + dtw) : 0.0;
  float sum = l.reflection + l.diffuse + l.glass + l.coat + l.sheen;
  float inv = sum > 0.0 ? 1.0 / sum : 0.0;
  l.reflection *= inv;
  l.diffuse *= inv;
  l.glass *= inv;
  l.coat *= inv;
  l.sheen *= inv;
  return l;
}

// The base layer's f * |wi.z| and its lobes' pdf (already weighted by their probabilities),
// wo and wi in the anisotropy frame.
vec3 bsdfEvalBase(BsdfParams p, BsdfLobes prob, vec3 wo, vec3 wi, inout float pdf) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  float dt = OSR_BSDF_LAYERS ? clamp(p.diffuseTransmission, 0.0, 1.0) : 0.0;
  vec2 alpha = ggxAlpha2(p);
  bool roughGlass = OSR_BSDF_TRANSMISSION && !glassIsDelta(p) && t > 0.0 && m < 1.0;
  vec3 f = vec3(0.0);
  if (wi.z > 0.0) {
    vec3 h = normalize(wo + wi);
    float voh = max(0.0, dot(wo, h));
    float spec = ggxD(h, alpha) * ggxG2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
    float hPdf = ggxVisiblePdf(wo, h, alpha) / (4.0 * max(voh, 1e-8));
    vec3 fm = metalFresnel(p, voh, wo.z);
    vec3 fd = dielectricFresnel(p, voh, wo.z);
    f += m * fm * spec;
    f += (1.0 - m) * (1.0 - t) *
         ((1.0 - p.specular * maxComponent(fd)) * (1.0 - dt) * p.baseColor * kInvPi +
          p.specular * fd * spec);
    pdf += prob.reflection * hPdf + prob.diffuse * (1.0 - prob.diffuseSplit) * wi.z * kInvPi;
    if (roughGlass) {
      float q;
      vec3 fr = glassFresnel(p, voh, wo.z, q);
      f += (1.0 - m) * t * fr * spec;
      pdf += prob.glass * q * hPdf;
    }
  } else {
    if (OSR_BSDF_LAYERS && dt > 0.0) {
      // Diffuse transmission: the Lambertian lobe's other half, its Fresnel weight at wo.
      float fo = maxComponent(dielectricFresnel(p, wo.z, wo.z));
      f += (1.0 - m) * (1.0 - t) * (1.0 - p.specular * fo) * dt * p.diffuseTransmissionColor *
           kInvPi;
      pdf += prob.diffuse * prob.diffuseSplit * -wi.z * kInvPi;
    }
    if (roughGlass) {
      // Refraction: the half vector of Walter et al. (2007), eq. 16, facing wo's side.
      vec3 h = normalize(wo + wi * p.eta);
      if (h.z < 0.0) h = -h;
      float voh = dot(wo, h);
      float ioh = dot(wi, h);
      if (voh > 0.0 && ioh < 0.0) {
        float q;
        vec3 fr = glassFresnel(p, voh, wo.z, q);
        float denom = ioh + voh / p.eta;
        denom *= denom;
        float d = ggxD(h, alpha);
        float g = ggxG2(wo, wi, alpha);
        f += (1.0 - m) * t * (1.0 - fr) * p.baseColor * d * g * abs(ioh * voh) /
             (wo.z * abs(wi.z) * denom);
        pdf += prob.glass * (1.0 - q) * ggxVisiblePdf(wo, h, alpha) * abs(ioh) / denom;
      }
    }
  }
  return f * abs(wi.z);
}

// The coat and sheen lobes' own f * |wi.z| and pdf (the base's scaling is the caller's).
vec3 bsdfEvalLayers(BsdfParams p, BsdfLobes prob, vec3 wo, vec3 wi, inout float pdf) {
  vec3 f = vec3(0.0);
  if (wi.z <= 0.0) return f;
  if (maxComponent(p.sheenColor) > 0.0) {
    f += p.sheenColor * sheenBrdf(p, wo, wi) * wi.z;
    pdf += prob.sheen * wi.z * kInvPi;
  }
  if (p.clearcoat > 0.0) {
    vec3 co = toCoat(p, wo), ci = toCoat(p, wi);
    if (co.z > 0.0 && ci.z > 0.0) {
      vec2 a = coatAlpha(p);
      vec3 h = normalize(co + ci);
      float voh = max(dot(co, h), 1e-8);
      float spec = ggxD(h, a) * ggxG2(co, ci, a) / (4.0 * co.z * ci.z);
      f += vec3(clamp(p.clearcoat, 0.0, 1.0) * coatFresnel(voh) * spec * wi.z);
      pdf += prob.coat * ggxVisiblePdf(co, h, a) / (4.0 * voh);
    }
  }
  return f;
}

// f * |wi.z| and the pdf of bsdfSample's continuous part for the pair (wo, wi), both already
// in the anisotropy frame.
vec3 bsdfEvalRotated(BsdfParams p, vec3 wo, vec3 wi, out float pdf) {
  pdf = 0.0;
  if (wo.z <= 0.0 || wi.z == 0.0) return vec3(0.0);
  BsdfLobes prob = bsdfLobeProbabilities(p, wo);
  vec3 f = bsdfEvalBase(p, prob, wo, wi, pdf);
  if (OSR_BSDF_LAYERS) {
    f *= sheenScaling(p, wo, wi) * (1.0 - coatWeight(p, wo));
    f += bsdfEvalLayers(p, prob, wo, wi, pdf);
  }
  return f;
}

// Moves the parameters' directions into the anisotropy frame (a no-op without anisotropy).
BsdfParams bsdfRotated(BsdfParams p) {
  if (OSR_BSDF_LAYERS && p.anisotropy > 0.0) p.clearcoatNormal = bsdfAnisoRotate(p, p.clearcoatNormal);
  return p;
}

vec3 bsdfEval(BsdfParams p, vec3 wo, vec3 wi, out float pdf) {
  if (OSR_BSDF_LAYERS && p.anisotropy > 0.0) {
    BsdfParams r = bsdfRotated(p);
    return bsdfEvalRotated(r, bsdfAnisoRotate(p, wo), bsdfAnisoRotate(p, wi), pdf);
  }
  return bsdfEvalRotated(p, wo, wi, pdf);
}

// Draws wi from the lobe mixture; u are three uniform numbers. False when no direction
// carries energy (black material, a sample below the surface).
bool bsdfSample(BsdfParams p, vec3 woIn, vec3 u, out BsdfSample s) {
  s.wi = vec3(0.0, 0.0, 1.0);
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.delta = false;
  if (woIn.z <= 0.0) return false;
  bool aniso = OSR_BSDF_LAYERS && p.anisotropy > 0.0;
  BsdfParams pr = aniso ? bsdfRotated(p) : p;
  vec3 wo = aniso ? bsdfAnisoRotate(p, woIn) : woIn;
  BsdfLobes prob = bsdfLobeProbabilities(pr, wo);
  float pR = prob.reflection, pD = pR + prob.diffuse, pG = pD + prob.glass;
  float pC = pG + prob.coat;
  if (pC + prob.sheen <= 0.0) return false;
  vec2 alpha = ggxAlpha2(pr);
  vec3 wi;
  if (u.x < pR) {
    vec3 h = ggxSampleVisible(wo, alpha, u.yz);
    wi = reflect(-wo, h);
    if (wi.z <= 0.0) return false;  // reflected below the horizon: energy the lobe loses
  } else if (u.x < pD || (!OSR_BSDF_TRANSMISSION && !OSR_BSDF_LAYERS)) {
    // (Without glass and layers only rounding of pD could reach past the diffuse lobe.)
    wi = sampleCosineHemisphere(u.yz);
    float ud = (u.x - pR) / max(prob.diffuse, 1e-12);
    if (OSR_BSDF_LAYERS && ud < prob.diffuseSplit) wi.z = -wi.z;
  } else if (OSR_BSDF_TRANSMISSION && u.x < pG) {
    // Reuse the lobe-selection number for the reflect/refract choice (it is uniform again
    // after rescaling to the glass interval).
    float uc = clamp((u.x - pD) / max(prob.glass, 1e-12), 0.0, 1.0);
    float m = clamp(pr.metallic, 0.0, 1.0);
    float t = clamp(pr.transmission, 0.0, 1.0);
    if (glassIsDelta(pr)) {
      float q;
      vec3 fr = glassFresnel(pr, wo.z, wo.z, q);
      s.delta = true;
      s.pdf = 0.0;
      if (uc < q) {
        wi = vec3(-wo.xy, wo.z);
        s.weight = (1.0 - m) * t * fr / (q * prob.glass);
      } else {
        wi = refract(-wo, vec3(0.0, 0.0, 1.0), 1.0 / pr.eta);
        // (q = 1 leaves no refraction: 1 - fr is 0 then, and the weight with it.)
        s.weight = (1.0 - m) * t * (1.0 - fr) * pr.baseColor / (max(1.0 - q, 1e-12) * prob.glass);
      }
      if (OSR_BSDF_LAYERS) s.weight *= sheenScaling(pr, wo, wi) * (1.0 - coatWeight(pr, wo));
      s.wi = aniso ? bsdfAnisoUnrotate(p, wi) : wi;
      return true;
    }
    vec3 h = ggxSampleVisible(wo, alpha, u.yz);
    float q;
    glassFresnel(pr, dot(wo, h), wo.z, q);
    if (uc < q) {
      wi = reflect(-wo, h);
      if (wi.z <= 0.0) return false;
    } else {
      wi = refract(-wo, h, 1.0 / pr.eta);
      if (wi.z >= 0.0) return false;  // refracted back up (or TIR, where fr = 1 anyway)
    }
  } else if (u.x < pC) {
    vec3 co = toCoat(pr, wo);
    if (co.z <= 0.0) return false;
    vec3 h = ggxSampleVisible(co, coatAlpha(pr), u.yz);
    wi = fromCoat(pr, reflect(-co, h));
    if (wi.z <= 0.0) return false;
  } else {
    wi = sampleCosineHemisphere(u.yz);  // sheen
  }
  if (wi.z == 0.0) return false;
  vec3 f = bsdfEvalRotated(pr, wo, wi, s.pdf);
  if (s.pdf <= 0.0) return false;
  s.weight = f / s.pdf;
  s.wi = aniso ? bsdfAnisoUnrotate(p, wi) : wi;
  return true;
}

// ---- Lobe split for OSR's control variate (osr_composite, osr_residual) ---------------------

// What the layers above leave to the base layer for (wo, wi): sheen scaling and coat.
float bsdfBaseScaling(BsdfParams p, vec3 wo, vec3 wi) {
  if (!OSR_BSDF_LAYERS) return 1.0;
  return sheenScaling(p, wo, wi) * (1.0 - coatWeight(p, wo));
}

// The diffuse reflection lobe's f * cos(wi) alone (wi.z > 0), exactly as bsdfEval includes it.
vec3 bsdfEvalDiffuse(BsdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  float dt = OSR_BSDF_LAYERS ? clamp(p.diffuseTransmission, 0.0, 1.0) : 0.0;
  float voh = max(0.0, dot(wo, normalize(wo + wi)));
  return (1.0 - m) * (1.0 - t) * (1.0 - dt) * bsdfBaseScaling(p, wo, wi) *
         (1.0 - p.specular * maxComponent(dielectricFresnel(p, voh, wo.z))) * p.baseColor * kInvPi * wi.z;
}

// A Lambertian reflectance standing in for the diffuse lobe at wo (its Fresnel weight and the
// layers' scaling taken at wo instead of at each wi): what the maps' closed-form irradiance
// is multiplied by.
vec3 bsdfDiffuseReflectance(BsdfParams p, vec3 wo) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  float dt = OSR_BSDF_LAYERS ? clamp(p.diffuseTransmission, 0.0, 1.0) : 0.0;
  return (1.0 - m) * (1.0 - t) * (1.0 - dt) * bsdfBaseScaling(p, wo, wo) *
         (1.0 - p.specular * maxComponent(dielectricFresnel(p, max(wo.z, 0.0), max(wo.z, 0.0)))) *
         p.baseColor;
}

// The GGX lobe's directional albedo for a Schlick Fresnel from f0 to f90 at wo.z: f0 A + f90 B,
// with (A, B) from Karis's fit of the split-sum table (Physically Based Shading on Mobile,
// 2014), close enough for a guide.
vec3 ggxDirectionalAlbedo(vec3 f0, float f90, float roughness, float cosO) {
  const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
  const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
  vec4 r = clamp(roughness, 0.0, 1.0) * c0 + c1;
  float a004 = min(r.x * r.x, exp2(-9.28 * clamp(cosO, 0.0, 1.0))) * r.x + r.y;
  vec2 ab = vec2(-1.04, 1.04) * a004 + r.zw;
  return f0 * ab.x + f90 * ab.y;
}

// The denoisers' albedo guide at wo: what the surface reflects of uniform light, the diffuse
// lobe as the maps take it (bsdfDiffuseReflectance) plus the base layer's GGX reflection (its
// tint: the metal's base colour, the dielectric's specular colour), glass as white, and the
// coat's share. Divided by it, the light on a glossy tiled floor is as smooth across the
// grout as the diffuse light is (the 4 % reflection is not the tiles' colour). Sheen and
// diffuse transmission are left out.
vec3 denoiseAlbedo(BsdfParams p, vec3 wo) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  vec3 f0 = dielectricF0(p);
  vec3 reflection = m * ggxDirectionalAlbedo(p.baseColor, 1.0, p.roughness, wo.z) +
                    (1.0 - m) * (1.0 - t) * p.specular *
                        ggxDirectionalAlbedo(f0, dielectricF90(f0), p.roughness, wo.z) +
                    vec3((1.0 - m) * t);
  float coat = coatWeight(p, wo);
  // Karis's fit dips a little below 0 for a black rough metal.
  return max(bsdfDiffuseReflectance(p, wo) + (1.0 - coat) * reflection + vec3(coat), vec3(0.0));
}

// The base layer's GGX reflection lobes (metal, dielectric specular, rough glass's reflection)
// f * cos(wi) alone (wi.z > 0), exactly as bsdfEval includes them: the part of f besides the
// diffuse lobe that OSR's composite takes from the maps. Clearcoat, sheen, diffuse
// transmission and refraction are not in it (osr_residual path-traces them).
vec3 bsdfEvalGlossy(BsdfParams p, vec3 woIn, vec3 wiIn) {
  if (woIn.z <= 0.0 || wiIn.z <= 0.0) return vec3(0.0);
  bool aniso = OSR_BSDF_LAYERS && p.anisotropy > 0.0;
  vec3 wo = aniso ? bsdfAnisoRotate(p, woIn) : woIn;
  vec3 wi = aniso ? bsdfAnisoRotate(p, wiIn) : wiIn;
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  vec2 alpha = ggxAlpha2(p);
  vec3 h = normalize(wo + wi);
  float voh = max(0.0, dot(wo, h));
  float spec = ggxD(h, alpha) * ggxG2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
  vec3 f = m * metalFresnel(p, voh, wo.z) * spec +
           (1.0 - m) * (1.0 - t) * p.specular * dielectricFresnel(p, voh, wo.z) * spec;
  float q;
  if (OSR_BSDF_TRANSMISSION && !glassIsDelta(p) && t > 0.0 && m < 1.0)
    f += (1.0 - m) * t * glassFresnel(p, voh, wo.z, q) * spec;
  return f * bsdfBaseScaling(p, woIn, wiIn) * wi.z;
}

// Samples the base GGX reflection lobe alone by visible normals: wi and its solid-angle pdf
// (0 when the reflection falls below the horizon).
vec3 bsdfSampleReflection(BsdfParams p, vec3 woIn, vec2 u, out float pdf) {
  bool aniso = OSR_BSDF_LAYERS && p.anisotropy > 0.0;
  vec3 wo = aniso ? bsdfAnisoRotate(p, woIn) : woIn;
  vec2 alpha = ggxAlpha2(p);
  vec3 h = ggxSampleVisible(wo, alpha, u);
  vec3 wi = reflect(-wo, h);
  float voh = max(dot(wo, h), 1e-8);
  pdf = wi.z > 0.0 ? ggxVisiblePdf(wo, h, alpha) / (4.0 * voh) : 0.0;
  return aniso ? bsdfAnisoUnrotate(p, wi) : wi;
}

#endif
