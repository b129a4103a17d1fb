// The glTF 2.0 metallic-roughness BSDF with KHR_materials_specular, _ior and _transmission,
// in the local frame (z = shading normal, wo.z > 0: the caller flips the frame for back-side
// hits and sets eta accordingly).
//   f = metallic * metal + (1 - metallic) * ((1 - t) * dielectric + t * glass)
//   metal      = F_schlick(baseColor, 1) * D G / (4 |wo.z| |wi.z|)              (glTF spec)
//   dielectric = (1 - specular * max(F)) * baseColor / pi + specular * F * D G / (4 ...)
//                F = F0 + (F90 - F0)(1 - v.h)^5, F0 = min(((ior-1)/(ior+1))^2 specularColor, 1)
//   glass      = rough dielectric BTDF/BRDF with exact Fresnel (Walter et al. 2007), or a
//                delta reflect/refract pair when alpha < kDeltaAlpha; refraction tinted by
//                baseColor. No 1/eta^2 radiance scaling (it cancels for a camera outside).
// D: GGX (Trowbridge-Reitz), G: height-correlated Smith (Heitz 2014); the GGX lobes are
// sampled by visible normals (Heitz 2018). F90 of the dielectric layer is
// specular * saturate(50 * max(F0)) (Filament's rule): a zero specular colour means "no
// specular at all", which is what Blender's exporter writes for a Lambertian Diffuse BSDF.
// bsdfEval returns f * |cos(wi)| and the solid-angle pdf of bsdfSample's continuous part.
#ifndef OSR_LIB_BSDF_GLSL
#define OSR_LIB_BSDF_GLSL
#include "lib/sampling.glsl"

// False where the includer knows no material transmits (pt_trace: kSceneFeatureTransmission):
// the glass lobe's code is then compiled out (on lavapipe a divergent branch costs all lanes).
#ifndef OSR_BSDF_TRANSMISSION
#define OSR_BSDF_TRANSMISSION true
#endif

const float kMinAlpha = 1e-3;
const float kDeltaAlpha = 1e-3;  // glass smoother than this is a perfect interface

struct BsdfSample {
  vec3 wi;
  vec3 weight;  // f * |cos| / pdf (delta lobes: the lobe's weight)
  float pdf;    // solid-angle pdf of the continuous part; 0 for delta samples
  bool delta;
};

float ggxAlpha(BsdfParams p) { return max(p.roughness * p.roughness, kMinAlpha); }
bool glassIsDelta(BsdfParams p) { return p.roughness * p.roughness < kDeltaAlpha; }

float ggxD(vec3 h, float a2) {
  float c2 = h.z * h.z;
  float d = c2 * (a2 - 1.0) + 1.0;
  return a2 / (kPi * d * d);
}

float ggxLambda(vec3 w, float a2) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0) return 1e30;
  float t2 = max(0.0, 1.0 - c2) / c2;
  return 0.5 * (-1.0 + sqrt(1.0 + a2 * t2));
}

float ggxG1(vec3 w, float a2) { return 1.0 / (1.0 + ggxLambda(w, a2)); }
float ggxG2(vec3 wo, vec3 wi, float a2) {
  return 1.0 / (1.0 + ggxLambda(wo, a2) + ggxLambda(wi, a2));
}

// Density of visible normals h seen from wo (wo.z > 0).
float ggxVisiblePdf(vec3 wo, vec3 h, float a2) {
  return ggxG1(wo, a2) * max(0.0, dot(wo, h)) * ggxD(h, a2) / wo.z;
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals".
vec3 ggxSampleVisible(vec3 wo, float alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
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
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-7, nh.z)));
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

vec3 dielectricFresnel(BsdfParams p, float voh) {
  vec3 f0 = dielectricF0(p);
  float f90 = clamp(50.0 * maxComponent(f0), 0.0, 1.0);
  return mix(f0, vec3(f90), schlickWeight(voh));
}

// Lobe selection probabilities at wo: x = GGX reflection (metal + dielectric specular),
// y = diffuse, z = glass. Zero everywhere for a black, non-transmissive material.
vec3 bsdfLobeProbabilities(BsdfParams p, vec3 wo) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  vec3 fm = mix(p.baseColor, vec3(1.0), schlickWeight(wo.z));
  float fd = p.specular * maxComponent(dielectricFresnel(p, wo.z));
  float wR = m * luminance(fm) + (1.0 - m) * (1.0 - t) * fd;
  float wD = (1.0 - m) * (1.0 - t) * (1.0 - fd) * luminance(p.baseColor);
  float wG = (1.0 - m) * t;
  float sum = wR + wD + wG;
  return sum > 0.0 ? vec3(wR, wD, wG) / sum : vec3(0.0);
}

// f * |wi.z| and the pdf of bsdfSample's continuous part for the pair (wo, wi).
vec3 bsdfEval(BsdfParams p, vec3 wo, vec3 wi, out float pdf) {
  pdf = 0.0;
  if (wo.z <= 0.0 || wi.z == 0.0) return vec3(0.0);
  vec3 prob = bsdfLobeProbabilities(p, wo);
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  float alpha = ggxAlpha(p);
  float a2 = alpha * alpha;
  bool roughGlass = OSR_BSDF_TRANSMISSION && !glassIsDelta(p) && t > 0.0 && m < 1.0;
  vec3 f = vec3(0.0);
  if (wi.z > 0.0) {
    vec3 h = normalize(wo + wi);
    float voh = max(0.0, dot(wo, h));
    float spec = ggxD(h, a2) * ggxG2(wo, wi, a2) / (4.0 * wo.z * wi.z);
    float hPdf = ggxVisiblePdf(wo, h, a2) / (4.0 * max(voh, 1e-8));
    vec3 fm = mix(p.baseColor, vec3(1.0), schlickWeight(voh));
    vec3 fd = dielectricFresnel(p, voh);
    f += m * fm * spec;
    f += (1.0 - m) * (1.0 - t) *
         ((1.0 - p.specular * maxComponent(fd)) * p.baseColor * kInvPi + p.specular * fd * spec);
    pdf += prob.x * hPdf + prob.y * wi.z * kInvPi;
    if (roughGlass) {
      float fr = fresnelDielectric(voh, p.eta);
      f += (1.0 - m) * t * fr * spec;
      pdf += prob.z * fr * hPdf;
    }
  } else if (roughGlass) {
    // Refraction: the half vector of Walter et al. (2007), eq. 16, facing wo's side.
    vec3 h = normalize(wo + wi * p.eta);
    if (h.z < 0.0) h = -h;
    float voh = dot(wo, h);
    float ioh = dot(wi, h);
    if (voh > 0.0 && ioh < 0.0) {
      float fr = fresnelDielectric(voh, p.eta);
      float denom = ioh + voh / p.eta;
      denom *= denom;
      float d = ggxD(h, a2);
      float g = ggxG2(wo, wi, a2);
      f = (1.0 - m) * t * (1.0 - fr) * p.baseColor * d * g * abs(ioh * voh) /
          (wo.z * abs(wi.z) * denom);
      pdf = prob.z * (1.0 - fr) * ggxVisiblePdf(wo, h, a2) * abs(ioh) / denom;
    }
  }
  return f * abs(wi.z);
}

// Draws wi from the lobe mixture; u are three uniform numbers. False when no direction
// carries energy (black material, a sample below the surface).
bool bsdfSample(BsdfParams p, vec3 wo, vec3 u, out BsdfSample s) {
  s.wi = vec3(0.0, 0.0, 1.0);
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.delta = false;
  if (wo.z <= 0.0) return false;
  vec3 prob = bsdfLobeProbabilities(p, wo);
  if (prob.x + prob.y + prob.z <= 0.0) return false;
  float alpha = ggxAlpha(p);
  if (u.x < prob.x) {
    vec3 h = ggxSampleVisible(wo, alpha, u.yz);
    s.wi = reflect(-wo, h);
    if (s.wi.z <= 0.0) return false;  // reflected below the horizon: energy the lobe loses
  } else if (!OSR_BSDF_TRANSMISSION || u.x < prob.x + prob.y) {
    // (Without transmission prob.z is 0; only rounding of prob.x + prob.y could reach glass.)
    s.wi = sampleCosineHemisphere(u.yz);
  } else {
    // Reuse the lobe-selection number for the reflect/refract choice (it is uniform again
    // after rescaling to the glass interval).
    float uc = clamp((u.x - prob.x - prob.y) / max(prob.z, 1e-12), 0.0, 1.0);
    float m = clamp(p.metallic, 0.0, 1.0);
    float t = clamp(p.transmission, 0.0, 1.0);
    if (glassIsDelta(p)) {
      float fr = fresnelDielectric(wo.z, p.eta);
      s.delta = true;
      s.pdf = 0.0;
      if (uc < fr) {
        s.wi = vec3(-wo.xy, wo.z);
        s.weight = vec3((1.0 - m) * t / prob.z);
      } else {
        s.wi = refract(-wo, vec3(0.0, 0.0, 1.0), 1.0 / p.eta);
        s.weight = (1.0 - m) * t * p.baseColor / prob.z;
      }
      return true;
    }
    vec3 h = ggxSampleVisible(wo, alpha, u.yz);
    float fr = fresnelDielectric(dot(wo, h), p.eta);
    if (uc < fr) {
      s.wi = reflect(-wo, h);
      if (s.wi.z <= 0.0) return false;
    } else {
      s.wi = refract(-wo, h, 1.0 / p.eta);
      if (s.wi.z >= 0.0) return false;  // refracted back up (or TIR, where fr = 1 anyway)
    }
  }
  if (s.wi.z == 0.0) return false;
  vec3 f = bsdfEval(p, wo, s.wi, s.pdf);
  if (s.pdf <= 0.0) return false;
  s.weight = f / s.pdf;
  return true;
}

// ---- Lobe split for OSR's control variate (osr_composite, osr_residual) ---------------------

// The diffuse lobe's f * cos(wi) alone (wi.z > 0), exactly as bsdfEval includes it.
vec3 bsdfEvalDiffuse(BsdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  float voh = max(0.0, dot(wo, normalize(wo + wi)));
  return (1.0 - m) * (1.0 - t) * (1.0 - p.specular * maxComponent(dielectricFresnel(p, voh))) *
         p.baseColor * kInvPi * wi.z;
}

// A Lambertian reflectance standing in for the diffuse lobe at wo (its Fresnel weight taken at
// wo instead of at each half vector): what the maps' closed-form irradiance is multiplied by.
vec3 bsdfDiffuseReflectance(BsdfParams p, vec3 wo) {
  float m = clamp(p.metallic, 0.0, 1.0);
  float t = OSR_BSDF_TRANSMISSION ? clamp(p.transmission, 0.0, 1.0) : 0.0;
  return (1.0 - m) * (1.0 - t) *
         (1.0 - p.specular * maxComponent(dielectricFresnel(p, max(wo.z, 0.0)))) * p.baseColor;
}

// Samples the GGX reflection lobe alone by visible normals: wi and its solid-angle pdf (0 when
// the reflection falls below the horizon).
vec3 bsdfSampleReflection(BsdfParams p, vec3 wo, vec2 u, out float pdf) {
  float alpha = ggxAlpha(p);
  vec3 h = ggxSampleVisible(wo, alpha, u);
  vec3 wi = reflect(-wo, h);
  float voh = max(dot(wo, h), 1e-8);
  pdf = wi.z > 0.0 ? ggxVisiblePdf(wo, h, alpha * alpha) / (4.0 * voh) : 0.0;
  return wi;
}

#endif
