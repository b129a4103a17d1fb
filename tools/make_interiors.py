#!/usr/bin/python3
"""Procedural interior scenes for training osr-vk's U-Net (glTF 2.0, seeded, reproducible).

usage: make_interiors.py OUT_DIR --seeds A-B [--seeds ...] [--cameras N]

Each seed S writes OUT_DIR/S/scene.gltf (+ scene.bin, its PNG textures, sky.hdr where the
scene opens onto an environment) and OUT_DIR/S/scene.json, which says what the scene holds and
which `osr-vk` options render it (the environment, the cameras). The same seed gives the same
files on any machine (Python's `random.Random`, no NumPy randomness).

What a scene holds, drawn per seed:
- a room of 2.8-9 m by 2.8-9 m, 2.4-3.8 m high, walls/floor/ceiling in matte paint, wallpaper
  or wood/tile textures;
- 0-3 windows and 0-1 door: windows open onto an emissive sky panel or the environment
  (a generated sky, sometimes with a sun as a directional light); a door onto a dim corridor;
- light of one of four kinds: ceiling panels, lamps (small emissive shades and point/spot
  lights), daylight only, or hidden up-lights so that light arrives mostly indirectly;
- furniture: tables, shelves, cabinets, columns, rugs, spheres, vases (lathed curves), wall
  mirrors, glass objects; materials matte, glossy and rough dielectrics, rough metals,
  mirrors, glass, textured;
- cameras at standing eye height (1.4-1.75 m), away from walls and furniture, looking across
  the room.

Scenes are generated, not committed: the seeds of the training and validation sets are in
docs/training.md (training 1-28, validation 9001-9005).
"""
from __future__ import annotations

import argparse
import json
import math
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from arg_types import parse_seeds, positive_int  # noqa: E402
from gltf_build import Gltf, REPEAT, png  # noqa: E402

Vec = tuple[float, float, float]


def add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(a: Vec, s: float) -> Vec:
    return (a[0] * s, a[1] * s, a[2] * s)


def cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a: Vec) -> Vec:
    n = math.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)
    return (a[0] / n, a[1] / n, a[2] / n)


class MeshBuilder:
    """Triangles of one material: positions, normals, uvs (in metres, for tiling textures)."""

    def __init__(self) -> None:
        self.p: list[Vec] = []
        self.n: list[Vec] = []
        self.uv: list[tuple[float, float]] = []
        self.i: list[int] = []

    def quad(self, origin: Vec, u: Vec, v: Vec, uv0=(0.0, 0.0), uv_scale: float = 1.0) -> None:
        """Parallelogram origin + [0,1]u + [0,1]v facing u x v."""
        normal = normalize(cross(u, v))
        lu, lv = math.dist((0, 0, 0), u), math.dist((0, 0, 0), v)
        base = len(self.p)
        for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
            self.p.append(add(origin, add(scale(u, a), scale(v, b))))
            self.n.append(normal)
            self.uv.append(((uv0[0] + a * lu) * uv_scale, (uv0[1] + (1 - b) * lv) * uv_scale))
        self.i += [base, base + 1, base + 2, base, base + 2, base + 3]

    def wall(self, origin: Vec, u: Vec, v: Vec, holes: list[tuple[float, float, float, float]]) -> None:
        """Rectangle origin + [0,1]u + [0,1]v minus holes (u0, u1, v0, v1 as fractions),
        split into the cells of the holes' breakpoints so no triangle spans an opening."""
        us = sorted({0.0, 1.0, *[h[0] for h in holes], *[h[1] for h in holes]})
        vs = sorted({0.0, 1.0, *[h[2] for h in holes], *[h[3] for h in holes]})
        lu, lv = math.dist((0, 0, 0), u), math.dist((0, 0, 0), v)
        for a0, a1 in zip(us, us[1:]):
            for b0, b1 in zip(vs, vs[1:]):
                cu, cv = (a0 + a1) / 2, (b0 + b1) / 2
                if any(h[0] <= cu <= h[1] and h[2] <= cv <= h[3] for h in holes):
                    continue
                o = add(origin, add(scale(u, a0), scale(v, b0)))
                self.quad(o, scale(u, a1 - a0), scale(v, b1 - b0), (a0 * lu, b0 * lv))

    def box(self, lo: Vec, hi: Vec, inward: bool = False) -> None:
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        faces = [((x0, y0, z1), (x1 - x0, 0, 0), (0, y1 - y0, 0)),   # +z
                 ((x1, y0, z0), (x0 - x1, 0, 0), (0, y1 - y0, 0)),   # -z
                 ((x1, y0, z1), (0, 0, z0 - z1), (0, y1 - y0, 0)),   # +x
                 ((x0, y0, z0), (0, 0, z1 - z0), (0, y1 - y0, 0)),   # -x
                 ((x0, y1, z1), (x1 - x0, 0, 0), (0, 0, z0 - z1)),   # +y
                 ((x0, y0, z0), (x1 - x0, 0, 0), (0, 0, z1 - z0))]   # -y
        for o, u, v in faces:
            if inward:
                o, u, v = add(o, u), scale(u, -1), v
            self.quad(o, u, v)

    def lathe(self, center: Vec, profile: list[tuple[float, float]], segments: int = 32) -> None:
        """Surface of revolution about the vertical axis through center; profile is (radius,
        height) from bottom to top, smooth normals from the profile's tangent."""
        cx, cy, cz = center
        rings = []
        for k, (r, y) in enumerate(profile):
            a = profile[max(k - 1, 0)]
            b = profile[min(k + 1, len(profile) - 1)]
            dr, dy = b[0] - a[0], b[1] - a[1]
            nr, ny = dy, -dr  # outward normal of the profile curve in (r, y)
            ln = math.hypot(nr, ny) or 1.0
            rings.append((r, y, nr / ln, ny / ln))
        base = len(self.p)
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            c, sn = math.cos(phi), math.sin(phi)
            for k, (r, y, nr, ny) in enumerate(rings):
                self.p.append((cx + r * c, cy + y, cz + r * sn))
                self.n.append((nr * c, ny, nr * sn))
                self.uv.append((s / segments * 2 * math.pi * max(r, 0.05), y))
        m = len(rings)
        for s in range(segments):
            for k in range(m - 1):
                a = base + s * m + k
                b = base + (s + 1) * m + k
                self.i += [a, a + 1, b + 1, a, b + 1, b]

    def sphere(self, center: Vec, radius: float, rings: int = 16) -> None:
        prof = [(radius * math.sin(math.pi * k / rings), -radius * math.cos(math.pi * k / rings))
                for k in range(rings + 1)]
        self.lathe(center, prof)

    def cylinder(self, bottom: Vec, radius: float, height: float) -> None:
        # Side with sharp rims: the caps are their own rings so their normals stay vertical.
        self.lathe(bottom, [(radius, 0.0), (radius, height)])
        self.disc(add(bottom, (0, height, 0)), radius, up=True)
        self.disc(bottom, radius, up=False)

    def disc(self, center: Vec, radius: float, up: bool, segments: int = 32) -> None:
        base = len(self.p)
        ny = 1.0 if up else -1.0
        self.p.append(center)
        self.n.append((0, ny, 0))
        self.uv.append((0, 0))
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            self.p.append(add(center, (radius * math.cos(phi), 0, radius * math.sin(phi))))
            self.n.append((0, ny, 0))
            self.uv.append((radius * math.cos(phi), radius * math.sin(phi)))
        for s in range(segments):
            a, b = base + 1 + s, base + 1 + (s + 1) % segments
            self.i += [base, b, a] if up else [base, a, b]


def texture_png(rng: random.Random, kind: str) -> bytes:
    """Procedural 8-bit textures: planks, tiles, checker, stripes, speckle."""
    n = 64
    c1 = [rng.randint(60, 230) for _ in range(3)]
    c2 = [max(0, min(255, c + rng.randint(-90, 90))) for c in c1]
    texels = []
    for y in range(n):
        for x in range(n):
            if kind == "planks":
                row = y // 8
                shade = ((row * 37 + (x + row * 23) // 40) % 5) / 5.0
                t = 0.7 + 0.3 * shade + 0.05 * math.sin(x * 0.9 + row)
                c = [int(v * t) for v in c1]
                if y % 8 == 0:
                    c = [v // 2 for v in c]
            elif kind == "tiles":
                c = c2 if (x % 16 == 0 or y % 16 == 0) else c1
            elif kind == "checker":
                c = c1 if ((x // 8) + (y // 8)) % 2 else c2
            elif kind == "stripes":
                c = c1 if (x // 6) % 2 else c2
            else:  # speckle
                h = (x * 73856093 ^ y * 19349663) & 0xFFFF
                c = c1 if h % 7 else c2
            texels.append((c[0], c[1], c[2], 255))
    return png(n, n, texels)


def write_sky_hdr(path: Path, rng: random.Random) -> None:
    """Equirectangular sky (Radiance RGBE, 128 x 64): zenith blue to a bright horizon over a
    dim ground, scaled so daylight through a window is of the order of a ceiling lamp."""
    w, h = 128, 64
    zenith = (rng.uniform(0.2, 0.5), rng.uniform(0.4, 0.7), rng.uniform(0.8, 1.2))
    horizon = (rng.uniform(0.9, 1.3), rng.uniform(0.9, 1.2), rng.uniform(0.8, 1.1))
    ground = [rng.uniform(0.1, 0.3)] * 3
    power = rng.uniform(1.0, 6.0)
    rows = bytearray()
    for j in range(h):
        theta = math.pi * (j + 0.5) / h  # 0 at the zenith (row 0 is up)
        elev = math.pi / 2 - theta
        for i in range(w):
            if elev >= 0:
                t = math.sin(elev) ** 0.5
                c = [power * (horizon[k] * (1 - t) + zenith[k] * t) for k in range(3)]
            else:
                c = [power * ground[k] for k in range(3)]
            m = max(c)
            if m < 1e-32:
                rows += b"\0\0\0\0"
                continue
            e = math.frexp(m)[1]
            f = 256.0 / 2.0 ** e
            rows += bytes([min(255, int(c[0] * f)), min(255, int(c[1] * f)), min(255, int(c[2] * f)), e + 128])
    head = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n".encode()
    path.write_bytes(head + bytes(rows))


class SceneBuilder:
    def __init__(self, seed: int, out: Path) -> None:
        self.rng = random.Random(seed)
        self.seed = seed
        self.out = out
        self.g = Gltf(f"osr-vk make_interiors.py seed {seed}")
        self.meshes: dict[int, MeshBuilder] = {}  # material index -> its triangles
        self.footprints: list[tuple[float, float, float, float]] = []  # x0, z0, x1, z1
        self.info: dict = {"seed": seed, "lights": [], "objects": [], "openings": []}
        self.textures = 0

    # Materials -----------------------------------------------------------------------------
    def material(self, name: str, color, metallic=0.0, roughness=0.8, emissive=None, strength=1.0,
                 transmission=0.0, ior=1.5, texture: str | None = None) -> int:
        m: dict = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": [*color, 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}}
        ext: dict = {}
        if emissive is not None:
            m["emissiveFactor"] = list(emissive)
            if strength != 1.0:
                ext["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
        if transmission > 0:
            ext["KHR_materials_transmission"] = {"transmissionFactor": transmission}
            ext["KHR_materials_ior"] = {"ior": ior}
        if texture:
            name_png = f"tex{self.textures}.png"
            self.textures += 1
            (self.out / name_png).write_bytes(texture_png(self.rng, texture))
            img = self.g.add("images", {"uri": name_png})
            smp = self.g.add("samplers", {"wrapS": REPEAT, "wrapT": REPEAT})
            tex = self.g.add("textures", {"source": img, "sampler": smp})
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": tex}
            m["pbrMetallicRoughness"]["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
        if ext:
            m["extensions"] = ext
            for key in ext:
                used = self.g.doc.setdefault("extensionsUsed", [])
                if key not in used:
                    used.append(key)
        return self.g.add("materials", m)

    def paint(self, name: str) -> int:
        r = self.rng
        if r.random() < 0.5:  # pale
            c = [r.uniform(0.55, 0.9) for _ in range(3)]
        else:
            base = r.uniform(0.15, 0.8)
            c = [min(0.95, max(0.03, base + r.uniform(-0.35, 0.35))) for _ in range(3)]
        return self.material(name, c, roughness=r.uniform(0.6, 1.0))

    def surface_material(self, name: str) -> int:
        """A material for furniture and objects, drawn from the kinds users render."""
        r = self.rng
        kind = r.choices(["matte", "glossy", "rough_metal", "mirror", "glass", "textured"],
                         [30, 20, 15, 5, 8, 15])[0]
        col = [r.uniform(0.05, 0.9) for _ in range(3)]
        if kind == "matte":
            return self.material(f"{name}_matte", col, roughness=r.uniform(0.7, 1.0))
        if kind == "glossy":
            return self.material(f"{name}_glossy", col, roughness=r.uniform(0.05, 0.35))
        if kind == "rough_metal":
            metal = r.choice([(0.95, 0.64, 0.54), (0.91, 0.92, 0.92), (1.0, 0.78, 0.34), (0.56, 0.57, 0.58)])
            return self.material(f"{name}_metal", metal, metallic=1.0, roughness=r.uniform(0.15, 0.6))
        if kind == "mirror":
            return self.material(f"{name}_mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)
        if kind == "glass":
            return self.material(f"{name}_glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0,
                                 ior=r.uniform(1.45, 1.6))
        return self.material(f"{name}_tex", col, roughness=r.uniform(0.4, 0.9),
                             texture=r.choice(["checker", "stripes", "speckle"]))

    def mesh(self, material: int) -> MeshBuilder:
        return self.meshes.setdefault(material, MeshBuilder())

    # Room ----------------------------------------------------------------------------------
    def room(self) -> None:
        r = self.rng
        self.W, self.D, self.H = r.uniform(2.8, 9.0), r.uniform(2.8, 9.0), r.uniform(2.4, 3.8)
        W, D, H = self.W, self.D, self.H
        floor = self.material("floor", (0.5, 0.4, 0.3), roughness=r.uniform(0.3, 0.9),
                              texture=r.choice(["planks", "tiles", "planks", None]))
        if r.random() < 0.3:
            floor = self.paint("floor")
        ceiling = self.material("ceiling", [r.uniform(0.75, 0.9)] * 3, roughness=0.95)
        self.mesh(floor).quad((0, 0, D), (W, 0, 0), (0, 0, -D))
        self.mesh(ceiling).quad((0, H, 0), (W, 0, 0), (0, 0, D))
        self.daylight = r.random() < 0.55
        self.sky = r.choice(["env", "panel"]) if self.daylight else None
        # Walls as (origin, u, v) facing into the room, and their openings.
        walls = [((0, 0, 0), (W, 0, 0), (0, H, 0)),      # z = 0, faces +z
                 ((W, 0, D), (-W, 0, 0), (0, H, 0)),     # z = D, faces -z
                 ((0, 0, D), (0, 0, -D), (0, H, 0)),     # x = 0, faces +x
                 ((W, 0, 0), (0, 0, D), (0, H, 0))]      # x = W, faces -x
        self.walls = walls
        holes: list[list] = [[] for _ in walls]
        if self.daylight:
            for _ in range(r.randint(1, 3)):
                wi = r.randrange(4)
                length = math.dist((0, 0, 0), walls[wi][1])
                width = min(r.uniform(0.7, 2.5), length * 0.6)
                u0 = r.uniform(0.1, 0.9 - width / length)
                sill = r.uniform(0.3, 1.0)
                top = min(H - 0.2, sill + r.uniform(0.8, 1.8))
                hole = (u0, u0 + width / length, sill / H, top / H)
                if all(hole[1] < h[0] - 0.05 or hole[0] > h[1] + 0.05 for h in holes[wi]):
                    holes[wi].append(hole)
                    self.opening(walls[wi], hole, "window")
        if r.random() < 0.4:
            wi = r.randrange(4)
            length = math.dist((0, 0, 0), walls[wi][1])
            width = 0.9 / length
            u0 = r.uniform(0.05, 0.95 - width)
            hole = (u0, u0 + width, 0.0, min(2.1, H - 0.1) / H)
            if all(hole[1] < h[0] - 0.05 or hole[0] > h[1] + 0.05 for h in holes[wi]):
                holes[wi].append(hole)
                self.opening(walls[wi], hole, "door")
        wall_mat = self.paint("walls")
        for k, (o, u, v) in enumerate(walls):
            m = wall_mat
            if r.random() < 0.25:
                m = self.material(f"wall{k}", (0.6, 0.6, 0.6), roughness=0.9,
                                  texture=r.choice(["stripes", "speckle", "tiles"]))
            elif r.random() < 0.25:
                m = self.paint(f"wall{k}")
            self.mesh(m).wall(o, u, v, holes[k])

    def opening(self, wall, hole, kind: str) -> None:
        """What lies behind a window (sky panel or environment) or a door (a corridor)."""
        r = self.rng
        o, u, v = wall
        n = normalize(cross(u, v))        # into the room
        out = scale(n, -1)
        p0 = add(o, add(scale(u, hole[0]), scale(v, hole[2])))
        du, dv = scale(u, hole[1] - hole[0]), scale(v, hole[3] - hole[2])
        self.info["openings"].append(kind)
        if kind == "window":
            # Frame: the wall's thickness as four thin quads (the reveal), light grey.
            frame = self.material("window_frame", (0.8, 0.8, 0.78), roughness=0.5)
            depth = scale(out, 0.15)
            fm = self.mesh(frame)
            fm.quad(p0, depth, dv)
            fm.quad(add(p0, du), dv, depth)
            fm.quad(p0, du, depth)
            fm.quad(add(p0, dv), depth, du)
            if self.sky == "panel":
                warm = r.random() < 0.3
                color = (1.0, 0.85, 0.65) if warm else (0.75, 0.85, 1.0)
                sky = self.material("sky_panel", (0, 0, 0), emissive=color, strength=r.uniform(3, 25))
                dist = r.uniform(0.3, 2.5)
                grow = dist * 1.2 + 0.3
                lu = math.dist((0, 0, 0), du)
                lv = math.dist((0, 0, 0), dv)
                uh, vh = normalize(du), normalize(dv)
                c = add(add(p0, scale(du, 0.5)), add(scale(dv, 0.5), scale(out, dist)))
                a = scale(uh, lu / 2 + grow)
                b = scale(vh, lv / 2 + grow)
                # The panel faces the room (its normal is n): origin at -a -b, edges 2b then 2a.
                self.mesh(sky).quad(add(c, scale(add(a, b), -1)), scale(b, 2), scale(a, 2))
                self.info["lights"].append("sky_panel")
        else:  # door: a corridor 1.2 m deep of the room's own wall paint, dimly lit at its end
            corridor = self.paint("corridor")
            depth = scale(out, r.uniform(1.0, 2.0))
            cm = self.mesh(corridor)
            cm.quad(p0, dv, depth)                  # side
            cm.quad(add(p0, du), depth, dv)         # other side
            cm.quad(p0, depth, du)                  # floor
            cm.quad(add(p0, dv), du, depth)         # ceiling
            if r.random() < 0.5:
                end = self.material("corridor_light", (0, 0, 0), emissive=(1.0, 0.9, 0.8),
                                    strength=r.uniform(0.5, 4.0))
                self.info["lights"].append("corridor")
            else:
                end = corridor
            self.mesh(end).quad(add(p0, depth), du, dv)

    # Lights --------------------------------------------------------------------------------
    def lights(self) -> None:
        r = self.rng
        W, D, H = self.W, self.D, self.H
        kinds = ["ceiling", "lamps", "indirect"]
        kind = r.choice(kinds) if not self.daylight or r.random() < 0.6 else "daylight"
        self.info["lighting"] = kind
        if kind == "ceiling":
            for _ in range(r.randint(1, 4)):
                s = r.uniform(0.2, 1.4)
                x, z = r.uniform(s, W - s), r.uniform(s, D - s)
                warm = r.uniform(0.75, 1.0)
                m = self.material("ceiling_panel", (0, 0, 0), emissive=(1.0, warm, warm * 0.9),
                                  strength=r.uniform(2, 40) / max(s * s, 0.1))
                self.mesh(m).quad((x - s / 2, H - 0.01, z - s / 2), (0, 0, s), (s, 0, 0))
                self.info["lights"].append("ceiling_panel")
        elif kind == "lamps":
            for _ in range(r.randint(1, 4)):
                x, z = r.uniform(0.4, W - 0.4), r.uniform(0.4, D - 0.4)
                y = r.uniform(0.8, H - 0.3)
                if r.random() < 0.5:  # an emissive shade
                    rad = r.uniform(0.06, 0.2)
                    m = self.material("lamp_shade", (0, 0, 0), emissive=(1.0, 0.85, 0.6),
                                      strength=r.uniform(20, 200))
                    self.mesh(m).sphere((x, y, z), rad, rings=10)
                    self.info["lights"].append("lamp_sphere")
                else:
                    spot = r.random() < 0.4
                    light = {"type": "spot" if spot else "point", "color": [1.0, r.uniform(0.8, 1.0), 0.8],
                             "intensity": r.uniform(30, 400)}
                    if spot:
                        light["spot"] = {"innerConeAngle": 0.3, "outerConeAngle": r.uniform(0.5, 1.0)}
                    li = self.g.add("lights", light)
                    self.g.doc.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": self.g.doc["lights"]}
                    node = {"translation": [x, y, z], "extensions": {"KHR_lights_punctual": {"light": li}}}
                    if spot:  # aim down, tilted: glTF spots shine along -Z
                        node["rotation"] = quat_look(normalize((r.uniform(-0.5, 0.5), -1.0, r.uniform(-0.5, 0.5))))
                    self.g.node(**node)
                    self.info["lights"].append(light["type"])
        elif kind == "indirect":
            # Up-lights on top of tall cabinets: the ceiling is what lights the room.
            for _ in range(r.randint(1, 3)):
                x, z = r.uniform(0.5, W - 0.5), r.uniform(0.5, D - 0.5)
                s = r.uniform(0.2, 0.6)
                top = r.uniform(1.6, H - 0.5)
                body = self.surface_material("uplight_body")
                self.mesh(body).box((x - s / 2, 0, z - s / 2), (x + s / 2, top, z + s / 2))
                m = self.material("uplight", (0, 0, 0), emissive=(1.0, 0.9, 0.75), strength=r.uniform(20, 120))
                self.mesh(m).quad((x - s / 2 + 0.02, top + 0.005, z + s / 2 - 0.02), (s - 0.04, 0, 0), (0, 0, -(s - 0.04)))
                self.footprints.append((x - s / 2, z - s / 2, x + s / 2, z + s / 2))
                self.info["lights"].append("uplight")
        if self.daylight and r.random() < 0.5:
            # A sun through the windows.
            d = normalize((r.uniform(-1, 1), -r.uniform(0.3, 1.2), r.uniform(-1, 1)))
            li = self.g.add("lights", {"type": "directional", "color": [1.0, 0.95, 0.85],
                                       "intensity": r.uniform(500, 3000)})
            self.g.doc.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": self.g.doc["lights"]}
            self.g.node(rotation=quat_look(d), extensions={"KHR_lights_punctual": {"light": li}})
            self.info["lights"].append("sun")
        if "KHR_lights_punctual" in self.g.doc.get("extensions", {}):
            used = self.g.doc.setdefault("extensionsUsed", [])
            if "KHR_lights_punctual" not in used:
                used.append("KHR_lights_punctual")

    # Furniture -----------------------------------------------------------------------------
    def place(self, w: float, d: float, against_wall: bool = False):
        """A free floor rectangle of w x d (x0, z0), or None after 40 tries."""
        r = self.rng
        for _ in range(40):
            if against_wall:
                side = r.randrange(4)
                if side == 0:
                    x0, z0 = r.uniform(0.05, self.W - w - 0.05), 0.02
                elif side == 1:
                    x0, z0 = r.uniform(0.05, self.W - w - 0.05), self.D - d - 0.02
                elif side == 2:
                    x0, z0 = 0.02, r.uniform(0.05, self.D - d - 0.05)
                else:
                    x0, z0 = self.W - w - 0.02, r.uniform(0.05, self.D - d - 0.05)
            else:
                if self.W - w - 0.3 <= 0.3 or self.D - d - 0.3 <= 0.3:
                    return None
                x0, z0 = r.uniform(0.3, self.W - w - 0.3), r.uniform(0.3, self.D - d - 0.3)
            rect = (x0, z0, x0 + w, z0 + d)
            if all(rect[2] < f[0] - 0.1 or rect[0] > f[2] + 0.1 or rect[3] < f[1] - 0.1 or rect[1] > f[3] + 0.1
                   for f in self.footprints):
                self.footprints.append(rect)
                return x0, z0
        return None

    def furniture(self) -> None:
        r = self.rng
        count = r.randint(3, 10)
        for _ in range(count):
            kind = r.choices(["table", "shelf", "cabinet", "column", "sphere", "vase", "rug", "mirror", "glass"],
                             [20, 12, 15, 6, 12, 10, 8, 7, 10])[0]
            self.info["objects"].append(kind)
            getattr(self, "add_" + kind)()

    def add_table(self) -> None:
        r = self.rng
        w, d, h = r.uniform(0.6, 1.8), r.uniform(0.5, 1.0), r.uniform(0.45, 0.8)
        at = self.place(w, d)
        if not at:
            return
        x, z = at
        m = self.mesh(self.surface_material("table"))
        m.box((x, h - 0.04, z), (x + w, h, z + d))
        leg = 0.05
        for lx, lz in ((x, z), (x + w - leg, z), (x, z + d - leg), (x + w - leg, z + d - leg)):
            m.box((lx, 0, lz), (lx + leg, h - 0.04, lz + leg))
        if r.random() < 0.6:  # something on it
            obj = self.mesh(self.surface_material("table_object"))
            rad = r.uniform(0.05, 0.15)
            cx, cz = r.uniform(x + rad, x + w - rad), r.uniform(z + rad, z + d - rad)
            if r.random() < 0.5:
                obj.sphere((cx, h + rad, cz), rad)
            else:
                obj.cylinder((cx, h, cz), rad, r.uniform(0.1, 0.4))

    def add_shelf(self) -> None:
        r = self.rng
        w, d, h = r.uniform(0.6, 1.6), r.uniform(0.25, 0.45), r.uniform(1.0, min(2.2, self.H - 0.2))
        at = self.place(w, d, against_wall=True)
        if not at:
            return
        x, z = at
        m = self.mesh(self.surface_material("shelf"))
        t = 0.03
        m.box((x, 0, z), (x + t, h, z + d))
        m.box((x + w - t, 0, z), (x + w, h, z + d))
        boards = r.randint(3, 6)
        for k in range(boards):
            y = k * (h - t) / (boards - 1)
            m.box((x + t, y, z), (x + w - t, y + t, z + d))
            if k < boards - 1 and r.random() < 0.7:  # books
                bm = self.mesh(self.surface_material("books"))
                bx = x + t + 0.02
                while bx < x + w - t - 0.1 and r.random() < 0.9:
                    bw = r.uniform(0.02, 0.06)
                    bh = min(r.uniform(0.15, 0.3), (h - t) / (boards - 1) - t - 0.02)
                    bm.box((bx, y + t, z + 0.03), (bx + bw, y + t + bh, z + d - 0.03))
                    bx += bw + 0.005

    def add_cabinet(self) -> None:
        r = self.rng
        w, d, h = r.uniform(0.4, 1.5), r.uniform(0.4, 0.7), r.uniform(0.4, 1.3)
        at = self.place(w, d, against_wall=r.random() < 0.7)
        if at:
            x, z = at
            self.mesh(self.surface_material("cabinet")).box((x, 0, z), (x + w, h, z + d))

    def add_column(self) -> None:
        r = self.rng
        rad = r.uniform(0.1, 0.3)
        at = self.place(2 * rad, 2 * rad)
        if at:
            mat = self.paint("column") if r.random() < 0.6 else self.surface_material("column")
            self.mesh(mat).cylinder((at[0] + rad, 0, at[1] + rad), rad, self.H)

    def add_sphere(self) -> None:
        r = self.rng
        rad = r.uniform(0.15, 0.5)
        at = self.place(2 * rad, 2 * rad)
        if at:
            self.mesh(self.surface_material("sphere")).sphere((at[0] + rad, rad, at[1] + rad), rad)

    def add_vase(self) -> None:
        r = self.rng
        rad = r.uniform(0.1, 0.25)
        h = r.uniform(0.3, 1.0)
        at = self.place(2 * rad, 2 * rad)
        if at:
            bulge = r.uniform(0.5, 1.0)
            prof = [(0.001, 0.0)] + [(rad * (0.4 + bulge * math.sin(math.pi * (k / 8) ** 0.8)), h * k / 8)
                                     for k in range(9)]
            self.mesh(self.surface_material("vase")).lathe((at[0] + rad, 0, at[1] + rad), prof)

    def add_rug(self) -> None:
        r = self.rng
        w, d = r.uniform(1.0, 3.0), r.uniform(0.8, 2.5)
        if w > self.W - 0.7 or d > self.D - 0.7:
            return
        x, z = r.uniform(0.3, self.W - w - 0.3), r.uniform(0.3, self.D - d - 0.3)
        m = self.material("rug", (0.5, 0.5, 0.5), roughness=1.0, texture=r.choice(["stripes", "checker", "speckle"]))
        self.mesh(m).box((x, 0, z), (x + w, 0.01, z + d))

    def add_mirror(self) -> None:
        r = self.rng
        o, u, v = self.walls[r.randrange(4)]
        n = normalize(cross(u, v))
        length = math.dist((0, 0, 0), u)
        w, h = min(r.uniform(0.4, 1.5), length * 0.5), r.uniform(0.5, 1.5)
        a = r.uniform(0.05, 1 - w / length - 0.05)
        y = r.uniform(0.6, max(0.7, self.H - h - 0.2))
        origin = add(add(o, scale(u, a)), add((0, y, 0), scale(n, 0.02)))
        mirror = self.material("mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=r.choice([0.0, 0.0, 0.05]))
        self.mesh(mirror).quad(origin, scale(normalize(u), w), (0, h, 0))

    def add_glass(self) -> None:
        r = self.rng
        glass = self.material("glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=r.uniform(1.45, 1.6))
        rad = r.uniform(0.1, 0.35)
        at = self.place(2 * rad, 2 * rad)
        if at:
            if r.random() < 0.5:
                self.mesh(glass).sphere((at[0] + rad, rad, at[1] + rad), rad)
            else:
                self.mesh(glass).box((at[0], 0, at[1]), (at[0] + 2 * rad, 2 * rad, at[1] + 2 * rad))

    # Cameras -------------------------------------------------------------------------------
    def cameras(self, count: int) -> None:
        r = self.rng
        made = 0
        for _ in range(200):
            if made == count:
                break
            x, z = r.uniform(0.4, self.W - 0.4), r.uniform(0.4, self.D - 0.4)
            if any(f[0] - 0.3 < x < f[2] + 0.3 and f[1] - 0.3 < z < f[3] + 0.3 for f in self.footprints):
                continue
            eye = (x, r.uniform(1.4, 1.75), z)
            # Look across the room: a target in the half of the room away from the eye.
            tx = r.uniform(0, self.W / 2) if x > self.W / 2 else r.uniform(self.W / 2, self.W)
            tz = r.uniform(0, self.D / 2) if z > self.D / 2 else r.uniform(self.D / 2, self.D)
            target = (tx, r.uniform(0.5, 1.5), tz)
            d = normalize((target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]))
            cam = self.g.add("cameras", {"type": "perspective", "name": f"view{made}",
                                         "perspective": {"yfov": math.radians(r.uniform(50, 75)), "aspectRatio": 1.0,
                                                         "znear": 0.05}})
            self.g.node(name=f"view{made}", camera=cam, translation=list(eye), rotation=quat_look(d))
            made += 1
        self.info["cameras"] = made

    def finish(self) -> None:
        for material, m in self.meshes.items():
            if not m.i:
                continue
            mesh = self.g.mesh(m.p, m.i, m.n, m.uv, material, index_type=5125)
            self.g.node(mesh=mesh)
        self.g.gltf(self.out / "scene.gltf", external_bin="scene.bin")


def quat_look(d: Vec) -> list[float]:
    """Unit quaternion (x, y, z, w) turning -Z onto direction d, +Y kept up where it can."""
    f = normalize(d)
    up = (0.0, 1.0, 0.0) if abs(f[1]) < 0.99 else (1.0, 0.0, 0.0)
    right = normalize(cross(f, up))
    u = cross(right, f)
    b = (-f[0], -f[1], -f[2])  # the local +Z axis
    m = [[right[0], u[0], b[0]], [right[1], u[1], b[1]], [right[2], u[2], b[2]]]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)
    return list(q)


def make_scene(seed: int, out: Path, cameras: int) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    b = SceneBuilder(seed, out)
    b.room()
    b.lights()
    b.furniture()
    b.cameras(cameras)
    b.finish()
    info = dict(b.info, room=[round(b.W, 3), round(b.D, 3), round(b.H, 3)], env=None)
    if b.sky == "env":
        write_sky_hdr(out / "sky.hdr", b.rng)
        info["env"] = "sky.hdr"
    (out / "scene.json").write_text(json.dumps(info, indent=1) + "\n")
    return info


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="make_interiors.py", description=__doc__.split("\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="output folder (one subfolder per seed)")
    p.add_argument("--seeds", action="append", required=True, help="seeds: 5, 1-20 or 1-10,40")
    p.add_argument("--cameras", type=positive_int, default=3, help="cameras per scene (default 3)")
    args = p.parse_args(argv)
    try:
        seeds = parse_seeds(args.seeds)
    except ValueError as e:
        print(f"make_interiors.py: --seeds: {e}", file=sys.stderr)
        return 2
    for s in seeds:
        info = make_scene(s, Path(args.out) / str(s), args.cameras)
        print(f"seed {s}: {info['lighting']}, {len(info['objects'])} objects, openings {info['openings']}, "
              f"{info['cameras']} cameras", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
