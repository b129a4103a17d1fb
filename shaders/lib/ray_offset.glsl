// Spawning secondary rays without self-intersection: moves the origin off the surface by a few
// ulps along the geometric normal, scaled with the magnitude of the coordinates (Wachter &
// Binder 2019, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems 6).
// Rays then start at t = 0 and need no scene-scale epsilon.
#ifndef OSR_LIB_RAY_OFFSET_GLSL
#define OSR_LIB_RAY_OFFSET_GLSL

// n: unit geometric normal on the side the new ray leaves towards.
vec3 offsetRayOrigin(vec3 p, vec3 n) {
  const float kOrigin = 1.0 / 32.0;
  const float kFloatScale = 1.0 / 65536.0;
  const float kIntScale = 256.0;
  ivec3 of = ivec3(kIntScale * n);
  vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -of.x : of.x)),
                 intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -of.y : of.y)),
                 intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -of.z : of.z)));
  return vec3(abs(p.x) < kOrigin ? p.x + kFloatScale * n.x : pi.x,
              abs(p.y) < kOrigin ? p.y + kFloatScale * n.y : pi.y,
              abs(p.z) < kOrigin ? p.z + kFloatScale * n.z : pi.z);
}

#endif
