// Random numbers for the path tracer: a PCG hash seeds one 32-bit PCG stream per
// (pixel, sample, seed), so every sample is reproducible from its indices alone and the
// image does not depend on dispatch size or order (Jarzynski & Olano 2020, "Hash Functions
// for GPU Rendering"). Independent uniform numbers; no low-discrepancy sequence yet.
#ifndef OSR_LIB_RNG_GLSL
#define OSR_LIB_RNG_GLSL

uint pcgHash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

struct Rng {
  uint state;
};

Rng rngInit(uint pixel, uint sampleIndex, uint seed) {
  Rng r;
  r.state = pcgHash(pixel ^ pcgHash(sampleIndex ^ pcgHash(seed + 0x9e3779b9u)));
  return r;
}

// Uniform in [0, 1): the top 24 bits, so 1.0 is never returned.
float rngNext(inout Rng r) {
  r.state = r.state * 747796405u + 2891336453u;
  uint word = ((r.state >> ((r.state >> 28u) + 4u)) ^ r.state) * 277803737u;
  word = (word >> 22u) ^ word;
  return float(word >> 8u) * (1.0 / 16777216.0);
}

vec2 rngNext2(inout Rng r) { return vec2(rngNext(r), rngNext(r)); }
vec3 rngNext3(inout Rng r) { return vec3(rngNext(r), rngNext(r), rngNext(r)); }

#endif
