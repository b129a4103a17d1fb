// Random numbers for the path tracer: a PCG hash seeds one 32-bit PCG stream per
// (pixel, sample, seed), so every sample is reproducible from its indices alone and the
// image does not depend on dispatch size or order (Jarzynski & Olano 2020, "Hash Functions
// for GPU Rendering"). The few dimensions that matter most (pixel jitter, the first bounce's
// light and BSDF samples) can instead come from sobolOwen2: 2-D Sobol points, Owen-scrambled
// and shuffled per pixel and dimension pair (Burley 2020, "Practical Hash-based Owen
// Scrambling"), so that they stay stratified across a pixel's samples.
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

// Laine-Karras style hash permutation with Burley's 2020 constants: flips each bit depending
// only on the bits below it, which after bit reversal is a nested uniform (Owen) scramble.
uint laineKarrasPermutation(uint x, uint seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}

uint nestedUniformScramble(uint x, uint seed) {
  return bitfieldReverse(laineKarrasPermutation(bitfieldReverse(x), seed));
}

// Second Sobol dimension: direction numbers v_k = v_{k-1} ^ (v_{k-1} >> 1), v_0 = 1 << 31, XORed
// over the set bits k of i. Reversed, v_k is row k of Pascal's triangle mod 2, whose entry j is
// odd exactly when j's bits are a subset of k's (Lucas), so bit j of the reversed result is the
// XOR of i's bits at every k that contains j: a superset sum over the 5-bit positions, five
// shift-mask-xor steps. The same bits as the loop over i's bits, which ran up to 32 iterations
// and was a large part of pt_trace's time (docs/pathtracer.md, "Benchmark"), and no branch.
uint sobolDimension1(uint i) {
  i ^= (i >> 1) & 0x55555555u;
  i ^= (i >> 2) & 0x33333333u;
  i ^= (i >> 4) & 0x0f0f0f0fu;
  i ^= (i >> 8) & 0x00ff00ffu;
  i ^= (i >> 16) & 0x0000ffffu;
  return bitfieldReverse(i);
}

// Point `index` of a shuffled, Owen-scrambled 2-D Sobol sequence; `seed` picks the scramble
// (use a different seed per pixel and per dimension pair). In [0, 1)^2.
vec2 sobolOwen2(uint index, uint seed) {
  index = nestedUniformScramble(index, seed);
  uint x = nestedUniformScramble(bitfieldReverse(index), pcgHash(seed ^ 0x68bc21ebu));
  uint y = nestedUniformScramble(sobolDimension1(index), pcgHash(seed ^ 0x02e5be93u));
  return vec2(float(x >> 8u), float(y >> 8u)) * (1.0 / 16777216.0);
}

#endif
