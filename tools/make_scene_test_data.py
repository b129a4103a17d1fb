#!/usr/bin/env python3
"""Writes the small hand-made glTF files of tests/data/scene (one per loader feature and one per
kind of bad input). The output is committed; rerun after changing this script:

    /usr/bin/python3 tools/make_scene_test_data.py tests/data/scene
"""
import argparse
import math
import struct
from pathlib import Path
from typing import Any

from gltf_build import (BYTE, CLAMP, FLOAT, MIRROR, NEAREST, REPEAT, SHORT, UBYTE, UINT, USHORT,
                        Gltf, data_uri, png)

GENERATOR = "osr-vk make_scene_test_data.py"


# A unit quad in the z = 0 plane facing +Z, two triangles, uv (0,0) at the top left.
QUAD_P = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
QUAD_N = [(0, 0, 1)] * 4
QUAD_UV = [(0, 1), (1, 1), (1, 0), (0, 0)]
QUAD_I = [0, 1, 2, 0, 2, 3]


def checker(n: int, a: tuple, b: tuple) -> bytes:
    return png(n, n, [a if (x + y) % 2 == 0 else b for y in range(n) for x in range(n)])


def hierarchy(out: Path) -> None:
    """Matrix parent, TRS child, mirrored node (det < 0), non-uniform scale on a slanted face."""
    g = Gltf(GENERATOR)
    quad = g.mesh(QUAD_P, QUAD_I, QUAD_N)
    # Slanted triangle: normal (0, 1, 1)/sqrt(2).
    s = 1 / math.sqrt(2)
    slant = g.mesh([(0, 0, 0), (1, 0, 0), (0, 1, -1)], [0, 1, 2], [(0, s, s)] * 3)
    child = g.node(root=False, name="child", mesh=quad, translation=[0, 1, 0],
                   rotation=[0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4)])  # 90 deg about Z
    # Column-major: uniform scale 2, translation (10, 0, 0).
    g.node(name="parent", matrix=[2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 10, 0, 0, 1], children=[child])
    g.node(name="mirrored", mesh=quad, scale=[-1, 1, 1], translation=[0, 0, 5])
    g.node(name="stretched", mesh=slant, scale=[1, 2, 1], translation=[0, 0, -5])
    g.gltf(out / "hierarchy.gltf")


def nonindexed(out: Path) -> None:
    """Two triangles without indices and without normals (flat normals generated)."""
    g = Gltf(GENERATOR)
    g.mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 2), (0, 1, 1)])
    g.node(name="tris", mesh=0)
    g.gltf(out / "nonindexed.gltf")


def index_types(out: Path) -> None:
    """The same quad indexed with u8, u16 and u32 indices; external .bin buffer."""
    g = Gltf(GENERATOR)
    for i, kind in enumerate([UBYTE, USHORT, UINT]):
        g.mesh(QUAD_P, QUAD_I, QUAD_N, index_type=kind)
        g.node(name=f"quad{i}", mesh=i, translation=[2.0 * i, 0, 0])
    g.gltf(out / "index_types.gltf", external_bin="index_types.bin")


def textured(out: Path) -> None:
    """Every texture slot: base colour from a PNG file, the others from data: URIs."""
    red, blue = (255, 0, 0, 255), (0, 0, 255, 128)
    (out / "checker.png").write_bytes(checker(4, red, blue))
    g = Gltf(GENERATOR)
    g.doc["images"] = [
        {"uri": "checker.png"},
        {"uri": data_uri(png(2, 2, [(0, 64, 255, 255), (0, 128, 128, 255), (0, 255, 0, 255), (0, 32, 64, 255)]), "image/png")},
        {"uri": data_uri(png(2, 1, [(200, 128, 255, 255), (128, 60, 200, 255)]), "image/png")},
        {"uri": data_uri(png(1, 2, [(255, 128, 0, 255), (0, 128, 255, 255)]), "image/png")},
        {"uri": data_uri(png(2, 2, [(255, 0, 0, 0), (128, 0, 0, 64), (64, 0, 0, 192), (0, 0, 0, 255)]), "image/png")},
    ]
    g.doc["samplers"] = [{"wrapS": REPEAT, "wrapT": REPEAT}, {"wrapS": CLAMP, "wrapT": MIRROR},
                         {"wrapS": MIRROR, "wrapT": CLAMP, "magFilter": NEAREST}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1},
                         {"source": 2, "sampler": 2}, {"source": 3}, {"source": 4, "sampler": 1}]
    g.doc["extensionsUsed"] = ["KHR_materials_specular", "KHR_materials_transmission"]
    g.add("materials", {
        "name": "textured",
        "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 1, 1], "baseColorTexture": {"index": 0},
                                 "metallicFactor": 0.5, "roughnessFactor": 0.8,
                                 "metallicRoughnessTexture": {"index": 1}},
        "normalTexture": {"index": 2, "scale": 0.7},
        "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 3},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.9, "specularTexture": {"index": 4},
                                                  "specularColorFactor": [1, 0.5, 0.25],
                                                  "specularColorTexture": {"index": 3}},
                       "KHR_materials_transmission": {"transmissionFactor": 0.6,
                                                      "transmissionTexture": {"index": 4}}}})
    # uvs beyond [0, 1] exercise the wrap modes.
    g.mesh(QUAD_P, QUAD_I, QUAD_N, [(-0.5, 1.75), (1.5, 1.75), (1.5, -0.75), (-0.5, -0.75)], material=0)
    # A rotated copy: the normal map's tangent frame must follow the uv layout.
    g.node(name="quad", mesh=0)
    g.node(name="rotated", mesh=0, translation=[3, 0, 0], rotation=[0.3, 0.2, 0.1, math.sqrt(1 - 0.14)])
    g.gltf(out / "textured.gltf")


def alpha_mask(out: Path) -> None:
    """MASK material with an alpha checker texture, next to an OPAQUE one with the same texture."""
    g = Gltf(GENERATOR)
    g.doc["images"] = [{"uri": data_uri(checker(2, (255, 255, 255, 255), (255, 255, 255, 0)), "image/png")}]
    g.doc["samplers"] = [{"wrapS": CLAMP, "wrapT": CLAMP}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}]
    g.add("materials", {"name": "mask", "alphaMode": "MASK", "alphaCutoff": 0.4,
                        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.add("materials", {"name": "opaque", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.add("materials", {"name": "blend", "alphaMode": "BLEND",
                        "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}})
    for m in range(3):
        g.mesh(QUAD_P, QUAD_I, QUAD_N, QUAD_UV, material=m)
        g.node(name=f"quad{m}", mesh=m, translation=[2.0 * m, 0, 0])
    g.gltf(out / "alpha_mask.gltf")


def lights(out: Path) -> None:
    """KHR_lights_punctual: point, spot and directional on transformed nodes."""
    g = Gltf(GENERATOR)
    # KHR_xmp_json_ld: metadata, loaded without a warning.
    g.doc["extensionsUsed"] = ["KHR_lights_punctual", "KHR_xmp_json_ld"]
    g.doc["asset"]["extensions"] = {"KHR_xmp_json_ld": {"packet": 0}}
    g.doc["extensions"] = {"KHR_xmp_json_ld": {"packets": [{"dc:creator": ["osr-vk"]}]},
                           "KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.5, 0.25], "intensity": 683, "range": 10},
        {"type": "spot", "intensity": 1366, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
        {"type": "directional", "color": [0.5, 0.5, 1], "intensity": 6.83}]}}
    g.mesh(QUAD_P, QUAD_I, QUAD_N)
    g.node(name="floor", mesh=0)
    g.node(name="point", translation=[1, 2, 3], extensions={"KHR_lights_punctual": {"light": 0}})
    # Rotated -90 deg about X: -Z points down (-Y).
    r = math.sqrt(0.5)
    g.node(name="spot", translation=[0, 4, 0], rotation=[-r, 0, 0, r],
           extensions={"KHR_lights_punctual": {"light": 1}})
    g.node(name="sun", extensions={"KHR_lights_punctual": {"light": 2}})
    g.gltf(out / "lights.gltf")


def cameras(out: Path) -> None:
    """Two perspective cameras (one without aspect ratio) and an orthographic one (skipped)."""
    g = Gltf(GENERATOR)
    g.doc["cameras"] = [
        {"type": "perspective", "name": "wide", "perspective": {"yfov": 1.2, "aspectRatio": 1.5, "znear": 0.1}},
        {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
        {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    g.mesh(QUAD_P, QUAD_I, QUAD_N)
    g.node(name="quad", mesh=0)
    g.node(name="cam0", camera=0, translation=[0, 0, 5])
    # Scaled node: the camera keeps only the rigid part.
    g.node(name="closeup", camera=1, translation=[0.5, 0.5, 2], scale=[3, 3, 3])
    g.node(name="ortho", camera=2)
    g.gltf(out / "cameras.gltf")


def materials(out: Path) -> None:
    """Factors of every supported extension, an unsupported extension, a lines primitive, and a
    primitive without material (gets the default material)."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_materials_specular", "KHR_materials_ior", "KHR_materials_transmission",
                               "KHR_materials_emissive_strength", "KHR_materials_dispersion"]
    g.add("materials", {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.95, 1, 1],
                                                                  "metallicFactor": 0, "roughnessFactor": 0.1},
                        "extensions": {"KHR_materials_ior": {"ior": 1.33},
                                       "KHR_materials_transmission": {"transmissionFactor": 1.0},
                                       "KHR_materials_specular": {"specularFactor": 0.5,
                                                                  "specularColorFactor": [0.2, 0.4, 0.6]},
                                       "KHR_materials_dispersion": {"dispersion": 0.5}}})
    g.add("materials", {"name": "lamp", "emissiveFactor": [1, 0.5, 0.25], "doubleSided": True,
                        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 40}}})
    g.add("materials", {"name": "dim", "emissiveFactor": [0.5, 0.5, 0.5]})
    g.mesh(QUAD_P, QUAD_I, QUAD_N, material=0)
    g.mesh(QUAD_P, QUAD_I, QUAD_N, material=1)
    g.mesh(QUAD_P, QUAD_I, QUAD_N, material=2)
    g.mesh(QUAD_P, [0, 1, 1, 2], mode=1)  # LINES: warned and skipped
    g.mesh(QUAD_P, QUAD_I, QUAD_N)  # no material
    g.node(name="glass", mesh=0)
    g.node(name="lamp", mesh=1, translation=[0, 0, 1], scale=[2, 3, 1])  # area 6
    g.node(name="dim", mesh=2, translation=[0, 0, 2])  # area 1, single-sided
    g.node(name="lines", mesh=3)
    g.node(name="plain", mesh=4, translation=[0, 0, 3])
    g.gltf(out / "materials.gltf")


def iridescence(out: Path) -> None:
    """KHR_materials_iridescence: every field and both textures, the draft's "iridescenceIOR"
    spelling, and the defaults."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_materials_iridescence"]
    # Factor in R, thickness in G (each texture read for its own channel only).
    g.doc["images"] = [{"uri": data_uri(png(2, 1, [(128, 10, 20, 255), (255, 200, 30, 255)]), "image/png")},
                       {"uri": data_uri(png(1, 2, [(5, 0, 6, 255), (7, 255, 8, 255)]), "image/png")}]
    g.doc["samplers"] = [{"wrapS": CLAMP, "wrapT": CLAMP}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}]
    g.add("materials", {"name": "film", "pbrMetallicRoughness": {"metallicFactor": 1, "roughnessFactor": 0.2},
                        "extensions": {"KHR_materials_iridescence": {
                            "iridescenceFactor": 0.8, "iridescenceTexture": {"index": 0},
                            "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 250,
                            "iridescenceThicknessMaximum": 650,
                            "iridescenceThicknessTexture": {"index": 1, "texCoord": 1}}}})
    g.add("materials", {"name": "draft", "extensions": {"KHR_materials_iridescence": {
        "iridescenceFactor": 1.0, "iridescenceIOR": 1.6}}})
    g.add("materials", {"name": "defaults", "extensions": {"KHR_materials_iridescence": {}}})
    for m in range(3):
        g.mesh(QUAD_P, QUAD_I, QUAD_N, QUAD_UV, material=m)
        g.node(name=f"quad{m}", mesh=m, translation=[2.0 * m, 0, 0])
    g.gltf(out / "iridescence.gltf")


def binary(out: Path) -> None:
    """.glb with the image in a buffer view; also the source of the truncated copy."""
    g = Gltf(GENERATOR)
    image = checker(2, (10, 20, 30, 255), (200, 210, 220, 255))
    g.doc["images"] = [{"bufferView": g.view(image), "mimeType": "image/png"}]
    g.doc["textures"] = [{"source": 0}]
    g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.mesh(QUAD_P, QUAD_I, QUAD_N, QUAD_UV, material=0, index_type=UINT)
    g.node(name="quad", mesh=0, translation=[0, 0, -1])
    g.glb(out / "quad.glb")
    data = (out / "quad.glb").read_bytes()
    (out / "bad_truncated.glb").write_bytes(data[: len(data) // 2])


def sparse_accessor(g: Gltf, base: int | None, indices: list[int], values: list) -> dict:
    """Makes accessor `base` (or a new one without buffer view, 4 elements) sparse."""
    flat = [c for v in values for c in v]
    sparse = {"count": len(indices),
              "indices": {"bufferView": g.view(struct.pack("<" + "B" * len(indices), *indices)),
                          "componentType": UBYTE},
              "values": {"bufferView": g.view(struct.pack("<" + "f" * len(flat), *flat))}}
    if base is None:
        g.doc["accessors"].append({"componentType": FLOAT, "count": 4, "type": "VEC3"})
        base = len(g.doc["accessors"]) - 1
    g.doc["accessors"][base]["sparse"] = sparse
    g.doc["accessors"][base].pop("min", None)
    g.doc["accessors"][base].pop("max", None)
    return g.doc["accessors"][base]


def sparse(out: Path) -> None:
    """Sparse POSITION accessors: one over a buffer view, one over zeros (no buffer view)."""
    g = Gltf(GENERATOR)
    g.mesh(QUAD_P, QUAD_I, QUAD_N)
    sparse_accessor(g, g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"], [2], [(1, 1, 1)])
    g.mesh(QUAD_P, QUAD_I, QUAD_N)
    sparse_accessor(g, None, [1, 2, 3], [(1, 0, 0), (1, 1, 0), (0, 1, 0)])
    g.doc["meshes"][1]["primitives"][0]["attributes"]["POSITION"] = len(g.doc["accessors"]) - 1
    g.node(name="over_view", mesh=0)
    g.node(name="over_zeros", mesh=1, translation=[0, 0, 2])
    g.gltf(out / "sparse.gltf")
    bad = Gltf(GENERATOR)
    bad.mesh(QUAD_P, QUAD_I, QUAD_N)
    sparse_accessor(bad, 0, [9], [(1, 1, 1)])
    bad.node(mesh=0)
    bad.gltf(out / "bad_sparse_index.gltf")


def vertex_attributes(out: Path) -> None:
    """COLOR_0 (normalized unsigned byte VEC4, float VEC3, normalized unsigned short VEC4) and
    TEXCOORD_1: base colour read through texCoord 1 (with its own KHR_texture_transform),
    emission through texCoord 0, on a 2 x 1 nearest texture (red | blue)."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_texture_transform"]
    g.doc["images"] = [{"uri": data_uri(png(2, 1, [(255, 0, 0, 255), (0, 0, 255, 255)]), "image/png")}]
    g.doc["samplers"] = [{"wrapS": CLAMP, "wrapT": CLAMP, "magFilter": NEAREST}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}]
    g.add("materials", {"name": "uv1",
                        "pbrMetallicRoughness": {"baseColorTexture": {
                            "index": 0, "texCoord": 1,
                            "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [0.5, 1]}}}},
                        "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}})
    g.add("materials", {"name": "plain", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1]}})
    colors = [
        (g.accessor([(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 128), (255, 255, 255, 0)], "VEC4", UBYTE, True), 0),
        (g.accessor([(1, 0.5, 0.25), (0.5, 0.5, 0.5), (0, 0, 0), (1, 1, 1)], "VEC3"), 1),
        (g.accessor([(65535, 0, 0, 65535), (0, 65535, 0, 32768), (0, 0, 65535, 65535), (65535, 65535, 65535, 0)], "VEC4", USHORT, True), 1),
    ]
    for m, (color, material) in enumerate(colors):
        mesh = g.mesh(QUAD_P, QUAD_I, QUAD_N, QUAD_UV, material=material)
        attributes = g.doc["meshes"][mesh]["primitives"][0]["attributes"]
        attributes["COLOR_0"] = color
        if m == 0:  # TEXCOORD_1: TEXCOORD_0 mirrored in u
            attributes["TEXCOORD_1"] = g.accessor([(1 - u, v) for u, v in QUAD_UV], "VEC2")
        g.node(name=f"quad{m}", mesh=mesh, translation=[2.0 * m, 0, 0])
    g.gltf(out / "vertex_attributes.gltf")


def texture16(out: Path) -> None:
    """A 16-bit-per-channel PNG: rounded to RGBA8."""
    g = Gltf(GENERATOR)
    g.doc["images"] = [{"uri": data_uri(png(2, 1, [(0x1234, 0xABCD, 0xFFFF, 0xFFFF), (0x00FF, 0x0100, 0x8000, 0x7FFF)], 16), "image/png")}]
    g.doc["textures"] = [{"source": 0}]
    g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.mesh(QUAD_P, QUAD_I, QUAD_N, QUAD_UV, material=0)
    g.node(name="quad", mesh=0)
    g.gltf(out / "texture16.gltf")


def degenerate_attributes(out: Path) -> None:
    """Loadable with warnings: a NaN uv, a zero normal, a texture whose image only an
    unsupported extension names."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["EXT_texture_webp"]
    g.doc["images"] = [{"uri": "never_read.webp"}]
    g.doc["textures"] = [{"extensions": {"EXT_texture_webp": {"source": 0}}}]
    g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.mesh(QUAD_P, QUAD_I, [(0, 0, 1), (0, 0, 0), (0, 0, 1), (0, 0, 1)],
           [(0, 1), (float("nan"), 1), (1, 0), (0, 0)], material=0)
    g.node(name="quad", mesh=0)
    g.gltf(out / "degenerate_attributes.gltf")


def texture_transform(out: Path) -> None:
    """KHR_texture_transform: offset + scale, the extension's rotated example, and a material whose
    slots disagree: base colour and normal map (the normal map's transform takes the uv1 slot)
    and a third transform on the emission (warned; the first slot's transform is used)."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_texture_transform"]
    g.doc["images"] = [{"uri": data_uri(checker(2, (255, 255, 255, 255), (0, 0, 0, 255)), "image/png")}]
    g.doc["textures"] = [{"source": 0}]
    shift = {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [0.5, 0.5]}}
    # "the lower left quadrant of the source image, rotated clockwise 90 degrees"
    quadrant = {"KHR_texture_transform": {"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}
    g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": shift}},
                        "emissiveTexture": {"index": 0, "extensions": shift}})
    g.add("materials", {"emissiveTexture": {"index": 0, "extensions": quadrant}})
    g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": shift}},
                        "normalTexture": {"index": 0}, "emissiveTexture": {"index": 0, "extensions": quadrant}})
    uv01 = [(0, 0), (1, 0), (1, 1), (0, 1)]
    for m in range(3):
        g.mesh(QUAD_P, QUAD_I, QUAD_N, uv01, material=m)
        g.node(name=f"quad{m}", mesh=m, translation=[2.0 * m, 0, 0])
    g.gltf(out / "texture_transform.gltf")


def quantized(out: Path) -> None:
    """KHR_mesh_quantization: int16 positions (scaled back by the node), int8 normalized
    normals, uint16 normalized uvs, positions in a strided buffer view."""
    g = Gltf(GENERATOR)
    g.doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    g.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    prim = {"attributes": {
        "POSITION": g.accessor([(0, 0, 0), (1000, 0, 0), (1000, 1000, 0), (0, 1000, 0)], "VEC3", SHORT, stride=8),
        "NORMAL": g.accessor([(0, 0, 127)] * 4, "VEC3", BYTE, normalized=True, stride=4),
        "TEXCOORD_0": g.accessor([(0, 65535), (65535, 65535), (65535, 0), (0, 0)], "VEC2", USHORT, normalized=True)},
        "indices": g.accessor(QUAD_I, "SCALAR", UBYTE)}
    g.doc["meshes"].append({"primitives": [prim]})
    g.node(name="quad", mesh=0, scale=[0.001, 0.001, 0.001])
    g.gltf(out / "quantized.gltf")


def animated(out: Path) -> None:
    """One node per sampler kind (hand-computed values in tests/scene/test_animation.cpp):
    STEP translation, LINEAR rotation (second key negated: slerp takes the short arc) with a
    LINEAR translation and a static child, CUBICSPLINE scale, a STEP scale that mirrors a flat
    shaded triangle, a moving camera, a still quad, and a morph-weights channel (skipped)."""
    g = Gltf(GENERATOR)
    quad = g.mesh(QUAD_P, QUAD_I, QUAD_N)
    flat = g.mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 2])
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]
    h = math.sqrt(0.5)
    stepper = g.node(name="stepper", mesh=quad)
    g.animate(stepper, "translation", [0, 1, 2], [(0, 0, 0), (1, 0, 0), (3, 0, 0)], "STEP")
    rider = g.node(root=False, name="rider", mesh=quad, translation=[1, 0, 0])
    spinner = g.node(name="spinner", mesh=quad, children=[rider])
    g.animate(spinner, "rotation", [0, 2], [(0, 0, 0, 1), (0, -h, 0, -h)])
    g.animate(spinner, "translation", [0, 2], [(0, 0, -2), (0, 2, -2)])
    bouncer = g.node(name="bouncer", mesh=quad)
    g.animate(bouncer, "scale", [0, 2], [(0, 0, 0), (1, 1, 1), (3, 0, 0),
                                         (0, 0, 0), (2, 1, 1), (0, 0, 0)], "CUBICSPLINE")
    flipper = g.node(name="flipper", mesh=flat, translation=[0, 0, 4])
    g.animate(flipper, "scale", [0, 1], [(1, 1, 1), (-1, 1, 1)], "STEP", animation=1)
    camera = g.node(name="camera", camera=0)
    g.animate(camera, "translation", [0, 2], [(0, 1, 5), (0, 1, 9)], animation=1)
    still = g.node(name="still", mesh=quad, translation=[0, -3, 0])
    g.animate(still, "weights", [0, 1], [0.0, 1.0], animation=1)
    g.gltf(out / "animated.gltf")


def camera_path(out: Path) -> None:
    """A lit corner (floor, back wall, a ceiling lamp, a leaning panel) seen by a camera that
    moves and turns over 0.25 s: the command-line frame tests render it at 24 frames/s."""
    g = Gltf(GENERATOR)
    g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1],
                                                  "metallicFactor": 0}})
    g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 1],
                                                  "metallicFactor": 0}})
    g.add("materials", {"emissiveFactor": [1, 1, 1],
                        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 8}}})
    g.doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    square = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
    up = [(0, 1, 0)] * 4
    facing = [0, 2, 1, 0, 3, 2]  # counter-clockwise seen from +Y
    g.mesh(square, facing, up, material=0)
    g.mesh(square, [0, 1, 2, 0, 2, 3], [(0, -1, 0)] * 4, material=2)  # facing down
    g.mesh(square, facing, up, material=1)
    g.node(name="floor", mesh=0, scale=[2, 1, 2])
    g.node(name="wall", mesh=0, translation=[0, 2, -2], rotation=[math.sqrt(0.5), 0, 0, math.sqrt(0.5)],
           scale=[2, 1, 2])
    g.node(name="lamp", mesh=1, translation=[0, 3, 0], scale=[0.5, 1, 0.5])
    g.node(name="panel", mesh=2, translation=[0.3, 0.6, -0.5], rotation=[0.3, 0.2, 0, 0.933],
           scale=[0.4, 1, 0.4])
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}]
    camera = g.node(name="camera", camera=0, translation=[0, 1.2, 4])
    g.animate(camera, "translation", [0, 0.25], [(-0.5, 1.2, 4), (0.5, 1.0, 3.5)])
    turn = math.radians(8) / 2
    g.animate(camera, "rotation", [0, 0.25],
              [(0, math.sin(-turn), 0, math.cos(turn)), (0, math.sin(turn), 0, math.cos(turn))])
    g.gltf(out / "camera_path.gltf")


def moving_object(out: Path) -> None:
    """A closed 4 m x 4 m x 2.5 m room lit by a ceiling panel and a point light, with a 0.3 m
    cube on the floor: the cube slides 0.4 m along +X from 0 to 1 s and holds; the point light
    moves 1 m along +Z from 2 to 3 s. A still camera sees the room from a corner. OSR's map
    cache tests (tests/osr/test_map_cache.cpp) and the command-line frame tests pose it."""
    g = Gltf(GENERATOR)
    g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1],
                                                  "metallicFactor": 0}})
    g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.25, 0.2, 1],
                                                  "metallicFactor": 0}})
    g.add("materials", {"emissiveFactor": [1, 1, 1],
                        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 6}}})
    g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.8, 1],
                                                  "metallicFactor": 0}})
    g.doc["extensionsUsed"] = ["KHR_materials_emissive_strength", "KHR_lights_punctual"]
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.9, 0.8], "intensity": 60}]}}

    def box(lo: tuple, hi: tuple, inward: bool) -> tuple[list, list, list]:
        """The six faces of a box, four vertices each, facing out (or in)."""
        p, n, idx = [], [], []
        for axis in range(3):
            for side in (0, 1):
                u, v = (axis + 1) % 3, (axis + 2) % 3
                normal = [0.0, 0.0, 0.0]
                normal[axis] = (1.0 if side else -1.0) * (-1.0 if inward else 1.0)
                base = len(p)
                for a, b in [(0, 0), (1, 0), (1, 1), (0, 1)]:
                    c = [0.0, 0.0, 0.0]
                    c[axis] = hi[axis] if side else lo[axis]
                    c[u] = hi[u] if a else lo[u]
                    c[v] = hi[v] if b else lo[v]
                    p.append(tuple(c))
                    n.append(tuple(normal))
                # (u, v) is counter-clockwise seen from +axis.
                ccw = (side == 1) != inward
                idx += [base, base + 1, base + 2, base, base + 2, base + 3] if ccw else \
                       [base, base + 2, base + 1, base, base + 3, base + 2]
        return p, n, idx

    walls_p, walls_n, walls_i = box((-2, 0, -2), (2, 2.5, 2), inward=True)
    g.mesh(walls_p[4:], [i - 4 for i in walls_i[6:]], walls_n[4:], material=0)  # all but x = -2
    g.mesh(walls_p[:4], walls_i[:6], walls_n[:4], material=1)  # a red wall at x = -2
    panel = [(-0.5, 2.49, -0.5), (0.5, 2.49, -0.5), (0.5, 2.49, 0.5), (-0.5, 2.49, 0.5)]
    g.mesh(panel, [0, 1, 2, 0, 2, 3], [(0, -1, 0)] * 4, material=2)  # facing down
    cube_p, cube_n, cube_i = box((-0.15, 0, -0.15), (0.15, 0.3, 0.15), inward=False)
    g.mesh(cube_p, cube_i, cube_n, material=3)
    g.node(name="walls", mesh=0)
    g.node(name="red_wall", mesh=1)
    g.node(name="panel", mesh=2)
    cube = g.node(name="cube", mesh=3, translation=[-1, 0, 0.5])
    g.animate(cube, "translation", [0, 1], [(-1, 0, 0.5), (-0.6, 0, 0.5)])
    lamp = g.node(name="lamp", translation=[1, 1.8, -1], extensions={"KHR_lights_punctual": {"light": 0}})
    g.animate(lamp, "translation", [2, 3], [(1, 1.8, -1), (1, 1.8, 0)])
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.1, "znear": 0.05}}]
    # In the +X +Z corner at 1.6 m, looking down across the room towards (-0.3, 0.5, -0.3).
    g.node(name="camera", camera=0, translation=[1.8, 1.6, 1.8],
           rotation=[-0.163, 0.3767, 0.0675, 0.9094])
    g.gltf(out / "moving_object.gltf")


def bad_inputs(out: Path) -> None:
    """One file per kind of bad input the loader must refuse with one line."""
    def quad_file(name: str, edit=None, positions=QUAD_P, indices=QUAD_I, **kw: Any) -> None:
        g = Gltf(GENERATOR)
        g.mesh(positions, indices, QUAD_N, **kw)
        g.node(name="quad", mesh=0)
        if edit:
            edit(g)
        g.gltf(out / name)

    good = Gltf(GENERATOR)
    good.mesh(QUAD_P, QUAD_I, QUAD_N)
    good.node(mesh=0)
    good.gltf(out / "bad_json.gltf")
    text = (out / "bad_json.gltf").read_text()
    (out / "bad_json.gltf").write_text(text[: len(text) // 3] + "\n")  # cut mid-object

    def accessor_count(g: Gltf) -> None:
        g.doc["accessors"][0]["count"] = 1000  # POSITION past its buffer view
    quad_file("bad_accessor_range.gltf", accessor_count)

    def view_length(g: Gltf) -> None:
        g.doc["bufferViews"][0]["byteLength"] = 100000  # view past the buffer
    quad_file("bad_buffer_view_range.gltf", view_length)

    def animation_times(g: Gltf) -> None:
        g.animate(0, "translation", [0, 2, 1], [(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    quad_file("bad_animation_times.gltf", animation_times)

    def animation_count(g: Gltf) -> None:
        g.animate(0, "scale", [0, 1], [(1, 1, 1), (2, 2, 2)], "CUBICSPLINE")  # needs 6 values
    quad_file("bad_animation_count.gltf", animation_count)

    quad_file("bad_index.gltf", indices=[0, 1, 2, 0, 2, 7])
    quad_file("bad_nan.gltf", positions=[(0, 0, 0), (1, 0, 0), (float("nan"), 1, 0), (0, 1, 0)])
    quad_file("bad_inf.gltf", positions=[(0, 0, 0), (1, 0, 0), (1, float("inf"), 0), (0, 1, 0)])

    def missing_image(g: Gltf) -> None:
        g.doc["images"] = [{"uri": "no_such_image.png"}]
        g.doc["textures"] = [{"source": 0}]
        g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        g.doc["meshes"][0]["primitives"][0]["material"] = 0
    quad_file("bad_missing_texture.gltf", missing_image)

    def no_triangles(g: Gltf) -> None:
        g.doc["meshes"][0]["primitives"][0]["mode"] = 0  # POINTS only
    quad_file("bad_no_triangles.gltf", no_triangles)

    g = Gltf(GENERATOR)
    g.mesh(QUAD_P, QUAD_I, QUAD_N)
    g.node(mesh=0)
    g.gltf(out / "bad_missing_bin.gltf", external_bin="bad_missing_bin.bin")
    (out / "bad_missing_bin.bin").unlink()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="output folder (tests/data/scene)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for make in [hierarchy, nonindexed, index_types, textured, alpha_mask, lights, cameras, materials,
                 iridescence, binary, sparse, quantized, texture16, degenerate_attributes, vertex_attributes,
                 texture_transform, animated, camera_path, moving_object, bad_inputs]:
        make(args.out)


if __name__ == "__main__":
    main()
