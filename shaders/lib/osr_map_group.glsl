// The two layouts of the passes that work on whole maps (osr_map_normalize, osr_map_denoise,
// osr_map_project), chosen by kOsrSpecMapByGroup (src/osr/osr_passes.h MapPassLayout):
//  - 0: one invocation per map, looping over its texels: lavapipe's SIMD lanes run maps side by
//    side, with no barriers or shared memory, which cost there;
//  - 1: a workgroup of kOsrWorkgroupSize per map, its invocations sharing the texels and
//    summing over them in shared memory: a GPU, where one invocation per map left 512 long,
//    uncoalesced threads per chunk of maps (docs/device_notes.md, "On an NVIDIA GPU").
// The includer declares local_size_x = kOsrWorkgroupSize. A map's invocations all return
// together (the map index is the workgroup's), so the barriers stay in uniform control flow.
#ifndef OSR_MAP_GROUP_GLSL
#define OSR_MAP_GROUP_GLSL

layout(constant_id = kOsrSpecMapByGroup) const uint kMapByGroup = 0u;

shared vec4 gMapGroupPartial[kOsrWorkgroupSize];

// The chunk's map this invocation works on.
uint mapOfInvocation() {
  return kMapByGroup != 0u ? gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x
                           : gl_GlobalInvocationID.x;
}

// The map's texels this invocation covers: t = firstMapTexel(); t < kMapTexels; t += mapTexelStep().
uint firstMapTexel() { return kMapByGroup != 0u ? gl_LocalInvocationID.x : 0u; }
uint mapTexelStep() { return kMapByGroup != 0u ? kOsrWorkgroupSize : 1u; }

// The sum over the map of each invocation's partial sums (every invocation gets it).
vec4 mapSum(vec4 partial) {
  if (kMapByGroup == 0u) return partial;
  uint lane = gl_LocalInvocationID.x;
  gMapGroupPartial[lane] = partial;
  barrier();
  for (uint half_ = kOsrWorkgroupSize / 2u; half_ > 0u; half_ /= 2u) {
    if (lane < half_) gMapGroupPartial[lane] += gMapGroupPartial[lane + half_];
    barrier();
  }
  vec4 total = gMapGroupPartial[0];
  barrier();  // before the next call overwrites it
  return total;
}

#endif
