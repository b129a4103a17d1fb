#!/usr/bin/env python3
"""Writes the hand-made material reference scenes of scenes/ (Lambertian surfaces, so that
Cycles, given the same glTF through Blender's importer, renders the same thing):

- alpha_blend: a lit box with a green card whose texture is alphaMode BLEND (alpha 0.25 /
  0.75 stripes and an opaque disc), in front of a blue wall; a MASK card beside it.
- emissive_texture: a dark box lit only by a screen whose emissive texture (8 x 4 coloured
  texels, KHR_materials_emissive_strength 6) is the light; COLOR_0 tints the floor.

    /usr/bin/python3 tools/make_material_scenes.py scenes
"""
import argparse
import math
from pathlib import Path

from gltf_build import CLAMP, NEAREST, Gltf, data_uri, png

GENERATOR = "osr-vk make_material_scenes.py"


def lambert(g: Gltf, color: tuple, **extra) -> int:
    """A Lambertian material as Blender's exporter writes one: specular colour 0, roughness 1."""
    m = {"pbrMetallicRoughness": {"baseColorFactor": [*color, 1.0], "metallicFactor": 0.0,
                                  "roughnessFactor": 1.0},
         "extensions": {"KHR_materials_specular": {"specularColorFactor": [0, 0, 0]}}}
    for k, v in extra.items():
        if k == "pbr":
            m["pbrMetallicRoughness"].update(v)
        elif k == "extensions":
            m["extensions"].update(v)
        else:
            m[k] = v
    return g.add("materials", m)


def quad(g: Gltf, corners: list, material: int, name: str, colors: list | None = None) -> None:
    """Corners counter-clockwise seen from the front; uv (0,0) at corner 0, (1,0) at corner 1."""
    a, b, c, d = corners
    e1 = [b[i] - a[i] for i in range(3)]
    e2 = [d[i] - a[i] for i in range(3)]
    n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    length = math.sqrt(sum(x * x for x in n))
    n = [x / length for x in n]
    mesh = g.mesh(list(corners), [0, 1, 2, 0, 2, 3], [n] * 4, [(0, 0), (1, 0), (1, 1), (0, 1)],
                  material=material)
    if colors is not None:
        g.doc["meshes"][mesh]["primitives"][0]["attributes"]["COLOR_0"] = g.accessor(colors, "VEC4")
    g.node(name=name, mesh=mesh)


def box(g: Gltf, white: int, colors: dict | None = None) -> None:
    """Floor, ceiling, back, left and right walls of the box x, z in [-1, 1], y in [0, 2], open
    towards +z (the camera)."""
    colors = colors or {}
    quad(g, [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)], colors.get("floor", white), "floor",
         colors.get("floor_colors"))
    quad(g, [(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)], colors.get("ceiling", white), "ceiling")
    quad(g, [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)], colors.get("back", white), "back")
    quad(g, [(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)], colors.get("left", white), "left")
    quad(g, [(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)], colors.get("right", white), "right")


def camera(g: Gltf) -> None:
    g.add("cameras", {"type": "perspective", "perspective": {"yfov": 0.75, "aspectRatio": 1.0,
                                                             "znear": 0.05}})
    g.node(name="camera", camera=0, translation=[0, 1, 3.4])


def texture(g: Gltf, w: int, h: int, texels: list) -> int:
    images = g.doc.setdefault("images", [])
    images.append({"uri": data_uri(png(w, h, texels), "image/png")})
    samplers = g.doc.setdefault("samplers", [])
    samplers.append({"wrapS": CLAMP, "wrapT": CLAMP, "magFilter": NEAREST, "minFilter": NEAREST})
    return g.add("textures", {"source": len(images) - 1, "sampler": len(samplers) - 1})


def alpha_blend(out: Path) -> None:
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_materials_specular", "KHR_materials_emissive_strength"]
    white = lambert(g, (0.8, 0.8, 0.8))
    blue = lambert(g, (0.15, 0.25, 0.7))
    red = lambert(g, (0.7, 0.15, 0.1))
    lamp = lambert(g, (0, 0, 0), emissiveFactor=[1, 1, 1], doubleSided=False,
                   extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}})
    # 8 x 8: columns alternate alpha 0.25 and 0.75 (in pairs), an opaque disc in the middle.
    texels = []
    for y in range(8):
        for x in range(8):
            disc = (x - 3.5) ** 2 + (y - 3.5) ** 2 < 5
            a = 255 if disc else (64 if (x // 2) % 2 == 0 else 191)
            texels.append((255, 255, 255, a))
    leaf = texture(g, 8, 8, texels)
    blend = lambert(g, (0.2, 0.7, 0.15), pbr={"baseColorTexture": {"index": leaf}},
                    alphaMode="BLEND", doubleSided=True)
    mask = lambert(g, (0.9, 0.6, 0.1), pbr={"baseColorTexture": {"index": leaf}},
                   alphaMode="MASK", alphaCutoff=0.5, doubleSided=True)
    box(g, white, {"back": blue, "left": red})
    # Facing down (the ceiling's winding): the lamp is single-sided.
    quad(g, [(-0.3, 1.999, -0.3), (0.3, 1.999, -0.3), (0.3, 1.999, 0.3), (-0.3, 1.999, 0.3)], lamp, "lamp")
    quad(g, [(-0.75, 0.25, 0.1), (0.15, 0.25, 0.1), (0.15, 1.15, 0.1), (-0.75, 1.15, 0.1)], blend, "blend card")
    quad(g, [(0.3, 0.2, -0.4), (0.9, 0.2, -0.4), (0.9, 0.8, -0.4), (0.3, 0.8, -0.4)], mask, "mask card")
    camera(g)
    g.gltf(out / "alpha_blend" / "alpha_blend.gltf")


def emissive_texture(out: Path) -> None:
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_materials_specular", "KHR_materials_emissive_strength"]
    white = lambert(g, (0.8, 0.8, 0.8))
    palette = [(255, 40, 20), (255, 200, 0), (20, 220, 60), (30, 90, 255), (0, 0, 0), (255, 255, 255)]
    texels = [(*palette[(3 * x + 5 * y) % len(palette)], 255) for y in range(4) for x in range(8)]
    screen_tex = texture(g, 8, 4, texels)
    screen = lambert(g, (0.05, 0.05, 0.05), emissiveFactor=[1, 1, 1],
                     emissiveTexture={"index": screen_tex}, doubleSided=False,
                     extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 6.0}})
    floor = lambert(g, (1.0, 1.0, 1.0))
    # Floor tinted by COLOR_0: warm at the front, cool at the back.
    floor_colors = [(0.9, 0.7, 0.5, 1), (0.9, 0.7, 0.5, 1), (0.4, 0.6, 0.9, 1), (0.4, 0.6, 0.9, 1)]
    box(g, white, {"floor": floor, "floor_colors": floor_colors})
    quad(g, [(-0.8, 0.6, -0.99), (0.8, 0.6, -0.99), (0.8, 1.4, -0.99), (-0.8, 1.4, -0.99)], screen, "screen")
    # A white block in the middle of the floor.
    s, h, cz = 0.25, 0.5, 0.0
    quad(g, [(-s, h, s + cz), (s, h, s + cz), (s, h, -s + cz), (-s, h, -s + cz)], white, "block top")
    quad(g, [(-s, 0, s + cz), (s, 0, s + cz), (s, h, s + cz), (-s, h, s + cz)], white, "block front")
    quad(g, [(s, 0, -s + cz), (-s, 0, -s + cz), (-s, h, -s + cz), (s, h, -s + cz)], white, "block back")
    quad(g, [(-s, 0, -s + cz), (-s, 0, s + cz), (-s, h, s + cz), (-s, h, -s + cz)], white, "block left")
    quad(g, [(s, 0, s + cz), (s, 0, -s + cz), (s, h, -s + cz), (s, h, s + cz)], white, "block right")
    camera(g)
    g.gltf(out / "emissive_texture" / "emissive_texture.gltf")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the scenes folder")
    args = parser.parse_args()
    for make in (alpha_blend, emissive_texture):
        make(args.out)


if __name__ == "__main__":
    main()
