// Reading the clean hemisphere maps of a pass (MapPoint, MapProjection, kOsrBindingMapClean):
// which maps a pixel uses and with what weight, radiance looked up in a world direction, and
// irradiance from a map's SH projection. Requires lib/osr_common.glsl.
#ifndef OSR_LIB_OSR_MAPS_GLSL
#define OSR_LIB_OSR_MAPS_GLSL

// World size of one pixel at a G-buffer surface (the ray length from the camera, through
// mirrors): the scale of the interpolation's plane distance.
float pixelFootprint(GBufferPixel g) {
  return g.wo.w * 2.0 * gFrame.tanHalfFovY / float(gFrame.imageHeight);
}

// The grid point of map `map` (cell map % cellsX, map / cellsX): a pixel of its cell, jittered
// per pass so that successive passes sample different points.
// With grid radius 0 the maps are at the pixels the host wrote into their points (MapTracer).
uvec2 mapPixel(MapGrid grid, uint map) {
  if (grid.radius == 0u) return gMapPoints[map].pixel.xy;
  uvec2 cell = uvec2(map % grid.cellsX, map / grid.cellsX);
  uint h = pcgHash(map ^ pcgHash(grid.seed));
  uvec2 jitter = uvec2(h & 0xffffu, h >> 16u) % grid.radius;
  return min(cell * grid.radius + jitter, uvec2(gFrame.width - 1u, gFrame.height - 1u));
}

// Radiance of map `map` arriving from local direction w (w.z > 0): the texel it falls in
// (piecewise constant, so that pi x the texel mean is the map's exact irradiance);
// cleanMapOffset: the map gMapClean's window starts at.
vec3 mapTexelRadiance(uint map, uint cleanMapOffset, uint texel) {
  uint base = (map - cleanMapOffset) * 3u * kMapTexels + texel;
  return vec3(gMapClean[base], gMapClean[base + kMapTexels], gMapClean[base + 2u * kMapTexels]);
}
vec3 mapRadianceLocal(uint map, uint cleanMapOffset, vec3 w) {
  uvec2 t = uvec2(hemiDirectionToSquare(w) * float(kMapSize));
  return mapTexelRadiance(map, cleanMapOffset,
                          min(t.y, kMapSize - 1u) * kMapSize + min(t.x, kMapSize - 1u));
}

// Real SH basis up to l = 2 (Ramamoorthi & Hanrahan 2001 ordering).
void shBasis(vec3 d, out float y[9]) {
  y[0] = 0.282095;
  y[1] = 0.488603 * d.y;
  y[2] = 0.488603 * d.z;
  y[3] = 0.488603 * d.x;
  y[4] = 1.092548 * d.x * d.y;
  y[5] = 1.092548 * d.y * d.z;
  y[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
  y[7] = 1.092548 * d.x * d.z;
  y[8] = 0.546274 * (d.x * d.x - d.y * d.y);
}

// The clamped cosine's SH factors A_l (Ramamoorthi & Hanrahan 2001): irradiance coefficients
// are radiance coefficients times A_l, for l = 0, 1, 1, 1, 2, 2, 2, 2, 2.
const float kShCosine[9] = float[9](kPi, 2.0 * kPi / 3.0, 2.0 * kPi / 3.0, 2.0 * kPi / 3.0,
                                    kPi / 4.0, kPi / 4.0, kPi / 4.0, kPi / 4.0, kPi / 4.0);

// Irradiance SH coefficients already carry the clamped-cosine convolution (A_l), so the
// irradiance at normal n is sum sh[i] Y_i(n).
vec3 shIrradiance(MapProjection m, vec3 nLocal) {
  float y[9];
  shBasis(nLocal, y);
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += m.sh[i].rgb * y[i];
  return e;
}

// Irradiance of map m's radiance at local normal nLocal: exact (pi x mean) at the map's own
// normal, corrected by the SH difference elsewhere; before the clamp at 0.
vec3 mapIrradianceUnclamped(MapProjection m, vec3 nLocal) {
  return kPi * m.mean.rgb + shIrradiance(m, nLocal) - shIrradiance(m, vec3(0.0, 0.0, 1.0));
}
vec3 mapIrradiance(MapProjection m, vec3 nLocal) {
  return max(mapIrradianceUnclamped(m, nLocal), vec3(0.0));
}

// A radiance over the whole sphere of directions whose clamped-cosine integral about ANY
// normal n is mapIrradianceUnclamped(m, n) exactly: the SH projection's own radiance
// (coefficients sh / A_l; by Funk-Hecke the cosine integral of a radiance band-limited to
// l <= 2 is sum A_l L_lm Y_lm(n)) plus the constant (pi mean - E_SH(z)) / pi that makes it
// exact at the map's normal. The residual's control variate for the diffuse lobe, so that
// it integrates the function whose integral the composite computes (docs/osr.md).
vec3 mapShRadiance(MapProjection m, vec3 wLocal) {
  float y[9];
  shBasis(wLocal, y);
  vec3 l = m.mean.rgb - shIrradiance(m, vec3(0.0, 0.0, 1.0)) * kInvPi;
  for (int i = 0; i < 9; ++i) l += m.sh[i].rgb * (y[i] / kShCosine[i]);
  return l;
}

// A map read from the cache was taken elsewhere, maybe in another view: its screen point is
// where its position projects in this one, or, nearer (through a mirror the projection is
// not where the surface shows), its world distance from x in pixel footprints at its grid
// point, laid off from p.
vec2 cachedMapScreenPoint(vec2 p, vec3 x, MapPoint m) {
  vec2 world = p + vec2(length(x - m.position.xyz) / max(m.normal.w, 1e-12), 0.0);
  vec2 projected;
  if (!cameraProject(gFrame, m.position.xyz, projected)) return world;
  return length(projected - p) < world.x - p.x ? projected : world;
}

// The maps a pixel draws on: the 3 x 3 cells around its own, with mapWeight weights.
struct MapGather {
  uint maps[9];
  float weights[9];
  uint count;
  float total;
  uint cleanMapOffset;  // the map gMapClean's window starts at
};

MapGather gatherMaps(MapGrid grid, uint cleanMapOffset, uvec2 pixel, vec3 x, vec3 n) {
  MapGather g;
  g.count = 0u;
  g.total = 0.0;
  g.cleanMapOffset = cleanMapOffset;
  int r = int(grid.radius);
  ivec2 cell = ivec2(pixel) / r;
  vec2 p = vec2(pixel) + 0.5;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 c = cell + ivec2(dx, dy);
      if (c.x < 0 || c.y < 0 || c.x >= int(grid.cellsX) || c.y >= int(grid.cellsY)) continue;
      uint map = uint(c.y) * grid.cellsX + uint(c.x);
      MapPoint m = gMapPoints[map];
      if (m.position.w < 0.5) continue;
      vec2 pg = vec2(m.pixel.xy) + 0.5;
      if (m.pixel.z != 0u) pg = cachedMapScreenPoint(p, x, m);
      float w = mapWeight(p, pg, float(r), x, n, m.position.xyz, m.normal.xyz,
                          m.normal.w * float(r));
      if (w <= 1e-6) continue;
      g.maps[g.count] = map;
      g.weights[g.count] = w;
      g.count += 1u;
      g.total += w;
    }
  }
  return g;
}

// Interpolated map radiance arriving from world direction `dir`, averaged over the maps whose
// hemisphere contains it; w: those maps' share of the gather's weight, 0 where no map's
// hemisphere contains it. On a curved surface a grazing direction lies below the hemispheres
// of the neighbouring maps: the maps know nothing there, so the glossy lobe's directions
// with w = 0 are left to the residual to path-trace in full (osr_residual), not counted black.
vec4 gatherRadiance(MapGather g, vec3 dir) {
  vec3 l = vec3(0.0);
  float total = 0.0;
  for (uint i = 0u; i < g.count; ++i) {
    mat3 frame = hemiFrame(gMapPoints[g.maps[i]].normal.xyz);
    vec3 w = transpose(frame) * dir;
    if (w.z > 0.0) {
      l += g.weights[i] * mapRadianceLocal(g.maps[i], g.cleanMapOffset, w);
      total += g.weights[i];
    }
  }
  return total > 0.0 ? vec4(l / total, total / g.total) : vec4(0.0);
}

// Drawing directions from the gathered maps (osr_residual's guided first bounce): a map with
// probability weight / total, one of its texels by luminance (MapProjection.rowLuminance, then
// the row's texels), a point uniform in the texel's square, which the cosine-weighted square
// map (shared/hemisphere.h) turns into a direction. Uniform in the square is cos / pi in solid
// angle, so one texel's density is its probability x kMapTexels x cos / pi.

// The solid-angle density of sampleGatheredMaps drawing world direction dir.
float gatheredMapsPdf(MapGather g, vec3 dir) {
  float pdf = 0.0;
  for (uint i = 0u; i < g.count; ++i) {
    float total = gMapProjections[g.maps[i]].mean.w;
    vec3 w = transpose(hemiFrame(gMapPoints[g.maps[i]].normal.xyz)) * dir;
    if (total <= 0.0 || w.z <= 0.0) continue;
    float lum = luminance(mapRadianceLocal(g.maps[i], g.cleanMapOffset, w));
    pdf += g.weights[i] * lum / total * float(kMapTexels) * w.z * kInvPi;
  }
  return g.total > 0.0 ? pdf / g.total : 0.0;
}

// False where the chosen map is black (a defective density: such draws count as zero
// samples, which gatheredMapsPdf's values keep unbiased). u: map, then texel; v: in the texel.
bool sampleGatheredMaps(MapGather g, vec2 u, vec2 v, out vec3 dir) {
  dir = vec3(0.0, 0.0, 1.0);
  if (g.count == 0u) return false;
  uint chosen = g.maps[g.count - 1u];
  float pick = u.x * g.total;
  for (uint i = 0u; i < g.count; ++i) {
    if (pick < g.weights[i]) {
      chosen = g.maps[i];
      break;
    }
    pick -= g.weights[i];
  }
  MapProjection m = gMapProjections[chosen];
  if (!(m.mean.w > 0.0)) return false;
  float left = u.y * m.mean.w;
  uint row = kMapSize;
  for (uint r = 0u; r < kMapSize; ++r) {
    float rowSum = m.rowLuminance[r / 4u][r % 4u];
    if (left < rowSum) {
      row = r;
      break;
    }
    left -= rowSum;
  }
  if (row == kMapSize) return false;  // rounding past the last texel
  uint column = kMapSize;
  for (uint c = 0u; c < kMapSize; ++c) {
    float lum = luminance(mapTexelRadiance(chosen, g.cleanMapOffset, row * kMapSize + c));
    if (left < lum) {
      column = c;
      break;
    }
    left -= lum;
  }
  if (column == kMapSize) return false;
  vec3 w = hemiSquareToDirection((vec2(column, row) + v) / float(kMapSize));
  dir = hemiFrame(gMapPoints[chosen].normal.xyz) * w;
  return w.z > 0.0;
}

// The diffuse control variate of a pixel with world normal n (osr_residual): per gathered map
// and channel, its normalized weight where gatherIrradiance(g, n) takes the map's irradiance
// and 0 where the clamp makes it 0, so that the cosine integral of gatherShRadiance about n
// is gatherIrradiance(g, n) exactly.
void gatherShWeights(MapGather g, vec3 n, out vec3 weights[9]) {
  for (uint i = 0u; i < g.count; ++i) {
    vec3 nLocal = transpose(hemiFrame(gMapPoints[g.maps[i]].normal.xyz)) * n;
    vec3 e = mapIrradianceUnclamped(gMapProjections[g.maps[i]], nLocal);
    weights[i] = vec3(greaterThan(e, vec3(0.0))) * (g.weights[i] / g.total);
  }
}
vec3 gatherShRadiance(MapGather g, vec3 weights[9], vec3 dir) {
  vec3 l = vec3(0.0);
  for (uint i = 0u; i < g.count; ++i) {
    vec3 w = transpose(hemiFrame(gMapPoints[g.maps[i]].normal.xyz)) * dir;
    l += weights[i] * mapShRadiance(gMapProjections[g.maps[i]], w);
  }
  return l;
}

// Interpolated irradiance at world normal n.
vec3 gatherIrradiance(MapGather g, vec3 n) {
  vec3 e = vec3(0.0);
  for (uint i = 0u; i < g.count; ++i) {
    vec3 nLocal = transpose(hemiFrame(gMapPoints[g.maps[i]].normal.xyz)) * n;
    e += g.weights[i] * mapIrradiance(gMapProjections[g.maps[i]], nLocal);
  }
  return g.total > 0.0 ? e / g.total : vec3(0.0);
}

#endif
