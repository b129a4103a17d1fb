#version 460
// osr_maps: one-shot hemisphere maps at the grid points of this pass, in bulk: one invocation
// per (map, texel) of a chunk. Texel (x, y) traces `pathsPerTexel` paths (1 for the one-shot input;
// many for reference maps) leaving the grid point's surface in a direction jittered inside
// the texel's cell of the cosine-concentric mapping (shared/hemisphere.h), in the frame of its
// shading normal. Radiance is light arriving after at least one bounce: emission of the first
// surface hit is excluded (it is the direct pass's), full depth with Russian roulette. Also
// writes the first hit's shading normal in the map frame (0 on a miss) and its distance (-1 on
// a miss). Texel 0 of each map writes its MapPoint (position, normal, pixel, footprint).
// Maps the cache gives (MapCacheRef kMapCacheReuse) are not traced.
// In: GBufferPixel, scene, BVH. Out: one-shot maps [chunk][7][32][32], MapPoint.
#extension GL_GOOGLE_include_directive : require
#include "lib/osr_common.glsl"
#include "lib/osr_maps.glsl"
#include "lib/osr_map_cache.glsl"

layout(local_size_x = kOsrWorkgroupSize) in;
layout(push_constant) uniform OsrPushBlock { MapsPush gPush; };
layout(std430, binding = kOsrBindingMapOneShot) writeonly buffer OsrOneShot { float gOneShot[]; };

void writeTexel(uint local, uint texel, vec3 radiance, vec3 normal, float distance) {
  uint base = local * kMapChannels * kMapTexels + texel;
  gOneShot[base] = radiance.r;
  gOneShot[base + kMapTexels] = radiance.g;
  gOneShot[base + 2u * kMapTexels] = radiance.b;
  gOneShot[base + 3u * kMapTexels] = normal.x;
  gOneShot[base + 4u * kMapTexels] = normal.y;
  gOneShot[base + 5u * kMapTexels] = normal.z;
  gOneShot[base + 6u * kMapTexels] = distance;
}

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * kOsrWorkgroupSize;
  uint local = id / kMapTexels;
  if (local >= gPush.mapCount) return;
  uint texel = id % kMapTexels;
  uint map = gPush.mapOffset + local;
  // The map cache's lookup gave this point a cached map (its MapPoint is written).
  if (gCacheRefs[map].action == kMapCacheReuse) return;
  uvec2 pixel = mapPixel(gPush.grid, map);
  GBufferPixel g = gGBuffer[pixel.y * gFrame.width + pixel.x - gPush.gbufferWindowOffset];
  bool valid = g.position.w > 0.5;
  if (texel == 0u) {
    MapPoint point;
    point.position = vec4(g.position.xyz, valid ? 1.0 : 0.0);
    // World size of one pixel at the point: the interpolation's plane-distance scale.
    point.normal = vec4(g.normal.xyz, pixelFootprint(g));
    point.pixel = uvec4(pixel, 0u, 0u);
    gMapPoints[map] = point;
  }
  if (!valid) {
    writeTexel(local, texel, vec3(0.0), vec3(0.0), -1.0);
    return;
  }
  ShadingPoint sp = gbufferShadingPoint(g);
  mat3 frame = hemiFrame(sp.ns);
  Rng rng = rngInit(map * kMapTexels + texel, gPush.pass, gFrame.seed ^ kSaltMaps);
  vec3 radiance = vec3(0.0);
  vec3 hitNormal = vec3(0.0);
  float distance = -1.0;
  uvec2 t = uvec2(texel % kMapSize, texel / kMapSize);
  // One flat loop over the bounces of successive paths, as in pt_trace: a lane whose path has
  // ended starts its next one at once. (Nested sample/bounce loops measured biased on
  // lavapipe: lanes whose path had ended kept adding light; see docs/osr.md.)
  uint s = 0u;
  PathState p;
  vec3 l = vec3(0.0);
  bool live = false;
  while (s < gPush.pathsPerTexel) {
    if (!live) {
      vec3 local3 = hemiSquareToDirection((vec2(t) + rngNext2(rng)) / float(kMapSize));
      vec3 dir = frame * local3;
      l = vec3(0.0);
      // Shading normals can put a direction below the geometric surface: it sees the surface.
      if (dot(dir, sp.ng) <= 0.0) {
        if (s == 0u) distance = 0.0;
        s += 1u;
        continue;
      }
      p = pathStart(shadingRayOrigin(sp, dir), dir, vec3(1.0), local3.z * kInvPi, sp.position, 1u);
      live = true;
    }
    uint bounce = p.bounce;
    vec3 uLight = rngNext3(rng);
    vec3 uBsdf = rngNext3(rng);
    float uRoulette = rngNext(rng);
    BounceResult r;
    bool ended = pathBounce(p, uLight, uBsdf, uRoulette, false, r);
    if (bounce == 1u) {
      if (s == 0u && r.hit) {
        hitNormal = transpose(frame) * r.normal;
        distance = length(r.position - sp.position);
      }
    } else {
      l += r.emitted;
    }
    l += r.nee;
    if (ended) {
      if (finite3(l)) radiance += l;
      live = false;
      s += 1u;
    }
  }
  writeTexel(local, texel, radiance / float(max(gPush.pathsPerTexel, 1u)), hitNormal, distance);
}
