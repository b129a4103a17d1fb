// The traversal loop of lib/bvh_traverse.glsl, included there twice: with OSR_BVH_LOOP_POOL 0
// it defines osrBvhTraverse (one ray), with 1 osrBvhTracePool (a subgroup's pool of rays). One
// text, so the two loops cannot drift apart; no include guard on purpose.
#if OSR_BVH_LOOP_POOL
// Traces rays [first, end) with this subgroup: each lane holds one ray at a time and takes the
// next index when its ray is done. Must be called in uniform control flow of the subgroup, with
// the same first and end on every lane.
void osrBvhTracePool(uint first, uint end, bool anyHit) {
  OsrBvhRay r;
  float tMin = 0.0, tFar = 0.0;
  Hit hit;
  bool found = false;
  uint ray = 0u;        // pool index of the lane's ray
  bool holding = false; // the lane has a ray whose result is not yet written
  uint next = first;    // first pool index not yet taken (uniform)
#else
bool osrBvhTraverse(vec3 origin, vec3 dir, float tMin, float tMax, bool anyHit, out Hit hit) {
  OsrBvhRay r = osrBvhMakeRay(origin, dir);
  hit.t = tMax;
  hit.triangle = 0xffffffffu;
  hit.barycentrics = vec2(0.0);
  bool found = false;
  float tFar = tMax;
#endif
  uint stack[kBvhMaxDepth];
  uint sp = 0u;
  uint node = 0u;
#if OSR_BVH_LOOP_POOL
  bool walking = false;
#else
  bool walking = true;  // `node` is still to be visited
#endif
  // Leaf ranges met by the walk and not yet intersected: (first entry, count), count 0 = none.
  uvec2 held0 = uvec2(0u), held1 = uvec2(0u);
  for (;;) {
#if OSR_BVH_LOOP_POOL
    // Lanes without a ray take the next ones, in lane order.
    uvec4 idle = subgroupBallot(!holding);
    uint slot = next + subgroupBallotExclusiveBitCount(idle);
    next += subgroupBallotBitCount(idle);
    if (!holding && slot < end) {
      OsrBvhPoolRayDesc d = osrBvhPoolRay(slot);
      r = osrBvhMakeRay(d.origin, d.dir);
      tMin = d.tMin;
      tFar = d.tMax;
      hit.t = d.tMax;
      hit.triangle = 0xffffffffu;
      hit.barycentrics = vec2(0.0);
      found = false;
      ray = slot;
      holding = true;
      walking = true;
      node = 0u;
      sp = 0u;
    }
    if (!subgroupAny(holding)) return;
#endif
    while (subgroupAny(walking && held0.y == 0u)) {
      // Every lane runs the step; lanes that wait (finished, or holding two ranges) change
      // nothing. Stores under a partial lane mask compile to a branch per lane on lavapipe.
      bool step = walking && held1.y == 0u;
      float ta, tb;
      bool ha, hb;
      uvec2 ref = osrBvhTestChildren(r, node, tMin, tFar, ha, ta, hb, tb);  // child references a, b
      ha = ha && step;
      hb = hb && step;
      bool leafA = ha && (ref.x & kBvhLeafFlag) != 0u;
      bool leafB = hb && (ref.y & kBvhLeafFlag) != 0u;
      // Two leaf children have consecutive entries (shared/bvh.h), so the hit ones are one range.
      uint count = (leafA ? (ref.x >> kBvhLeafCountShift) & kBvhLeafCountMask : 0u) +
                   (leafB ? (ref.y >> kBvhLeafCountShift) & kBvhLeafCountMask : 0u);
      uvec2 range = uvec2((leafA ? ref.x : ref.y) & kBvhLeafFirstMask, count);
      bool first = held0.y == 0u;
      held0 = count != 0u && first ? range : held0;
      held1 = count != 0u && !first ? range : held1;
      ha = ha && !leafA;
      hb = hb && !leafB;
      bool aFirst = ta <= tb;
      // The far child is written whether or not it is pushed (see above).
      stack[sp] = aFirst ? ref.y : ref.x;
      uint popped = stack[max(sp, 1u) - 1u];
      if (ha && hb) {
        sp++;
        node = aFirst ? ref.x : ref.y;
      } else if (ha || hb) {
        node = ha ? ref.x : ref.y;
      } else if (step) {
        walking = sp > 0u;
        if (walking) {
          node = popped;
          sp--;
        }
      }
    }
    // held0 before held1: the walk met it first, so it tends to be nearer.
    for (uint k = 0u; k < held0.y + held1.y; ++k) {
      uint i = k < held0.y ? held0.x + k : held1.x + (k - held0.y);
      BvhLeafTriangle tri = osrBvhLeafTriangle(i);
      float t;
      vec2 bary;
      if (!osrBvhTriangle(r, tri.v0.xyz, tri.v1.xyz, tri.v2.xyz, tMin, tFar, t, bary)) continue;
      uint id = floatBitsToUint(tri.v0.w);
#ifdef OSR_BVH_ALPHA_TEST
      if (osrAlphaCutout(id, bary, r.origin, r.invDir)) continue;
#endif
      found = true;
      hit.t = t;
      hit.triangle = id;
      hit.barycentrics = bary;
      tFar = t;
      if (anyHit) {  // done: the walk stops here
        walking = false;
        break;
      }
    }
    held0 = uvec2(0u);
    held1 = uvec2(0u);
#if OSR_BVH_LOOP_POOL
    if (holding && !walking) {
      osrBvhPoolResult(ray, found, hit);
      holding = false;
    }
#else
    if (!walking) break;
#endif
  }
#if !OSR_BVH_LOOP_POOL
  return found;
#endif
}
