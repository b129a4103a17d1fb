// The glTF metallic-roughness BSDF's inputs after texture lookups, as the shaders see them
// (shaders/lib/bsdf.glsl). Also the case record of pt_bsdf_probe.comp, the BSDF test pass.
#ifndef OSR_SHARED_BSDF_H
#define OSR_SHARED_BSDF_H
#include "shared/types.h"
OSR_NAMESPACE_BEGIN(bsdf)

struct BsdfParams {
  vec3 baseColor;
  float metallic;
  vec3 specularColor;  // KHR_materials_specular colour (dielectric F0 tint)
  float roughness;     // perceptual; GGX alpha = roughness^2
  float specular;      // KHR_materials_specular factor (dielectric specular weight)
  float eta;           // ior of the side wo is not on over the side it is on (1/ior when leaving)
  float transmission;  // KHR_materials_transmission
  float _pad0;
  // Layered lobes (all zero: the plain metallic-roughness BSDF above).
  vec3 clearcoatNormal;  // local frame (z = shading normal), on wo's side
  float clearcoat;       // KHR_materials_clearcoat weight
  vec3 sheenColor;       // KHR_materials_sheen
  float sheenRoughness;  // perceptual
  vec3 diffuseTransmissionColor;  // KHR_materials_diffuse_transmission
  float diffuseTransmission;
  vec2 anisotropyDirection;  // local frame xy, unit: direction of increased roughness
  float anisotropy;          // KHR_materials_anisotropy strength
  float clearcoatRoughness;  // perceptual
  float iridescence;           // KHR_materials_iridescence factor (0: no thin film)
  float iridescenceIor;        // the film's ior
  float iridescenceThickness;  // nanometres, > 0 where iridescence > 0
  float _pad1;
};

// pt_bsdf_probe.comp: for each case, either evaluates f*cos and pdf on a (theta, phi) grid
// over the whole sphere (mode kProbeEval) or draws samples (mode kProbeSample).
OSR_CONST(uint, kProbeWorkgroupSize, 64);
OSR_CONST(uint, kProbeEval, 0u);
OSR_CONST(uint, kProbeSample, 1u);
OSR_CONST(uint, kProbeGuide, 2u);  // one output per case: value = denoiseAlbedo at wo
OSR_CONST(uint, kProbeBindingCases, 0);
OSR_CONST(uint, kProbeBindingOut, 1);
OSR_CONST(uint, kProbeBindingCount, 2);

struct ProbeCase {
  BsdfParams params;
  vec4 wo;  // xyz: outgoing direction in the local frame (z = normal), z > 0
};

struct ProbePush {
  uint mode;
  uint caseCount;
  uint thetaCount;  // eval grid: theta in [0, pi] (midpoints)
  uint phiCount;    // eval grid: phi in [0, 2 pi)
  uint samplesPerCase;
  uint seed;
  uint _pad0;
  uint _pad1;
};

// One output record: eval mode fills value (f*|cos|) and pdf; sample mode fills value with the
// sample weight, pdf with the sample's pdf, evalValue/evalPdf with bsdfEval at the sampled
// direction (so the test can check that sampling and evaluation agree), flags bit 0 = delta,
// bit 1 = valid.
struct ProbeOut {
  vec3 value;
  float pdf;
  vec3 evalValue;
  float evalPdf;
  vec3 wi;
  uint flags;
};

OSR_NAMESPACE_END
#endif
