"""Small hand-written glTF scenes, one per layered-lobe extension (scenes/lobes/*.gltf).

Each: a grey Lambertian floor, one object with the extension's material, an emissive quad
light, a camera; the geometry is generated here (UV sphere, quads) and embedded as base64.
Run: python3 tools/lobe_scenes.py scenes/lobes
"""
import base64
import json
import math
import struct
import sys


def sphere(cx, cy, cz, radius, nu=48, nv=24):
    pos, nrm, uv, idx = [], [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            pos.append((cx + radius * n[0], cy + radius * n[1], cz + radius * n[2]))
            nrm.append(n)
            uv.append((i / nu, j / nv))
    for j in range(nv):
        for i in range(nu):
            a, b = j * (nu + 1) + i, (j + 1) * (nu + 1) + i
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, nrm, uv, idx


def quad(corner, du, dv, normal):
    p = [corner, tuple(corner[k] + du[k] for k in range(3)),
         tuple(corner[k] + du[k] + dv[k] for k in range(3)), tuple(corner[k] + dv[k] for k in range(3))]
    return p, [normal] * 4, [(0, 0), (1, 0), (1, 1), (0, 1)], [0, 1, 2, 0, 2, 3]


class Gltf:
    def __init__(self):
        self.data = bytearray()
        self.g = {"asset": {"version": "2.0", "generator": "osr-vk tools/lobe_scenes.py"},
                  "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                  "materials": [], "accessors": [], "bufferViews": [], "buffers": []}

    def view(self, blob, target):
        while len(self.data) % 4:
            self.data.append(0)
        self.g["bufferViews"].append({"buffer": 0, "byteOffset": len(self.data),
                                      "byteLength": len(blob), "target": target})
        self.data += blob
        return len(self.g["bufferViews"]) - 1

    def accessor(self, values, kind):
        n = len(values[0]) if kind != "SCALAR" else 1
        if kind == "SCALAR":
            blob = struct.pack("<%dI" % len(values), *values)
            v = self.view(blob, 34963)
            self.g["accessors"].append({"bufferView": v, "componentType": 5125,
                                        "count": len(values), "type": "SCALAR"})
        else:
            flat = [x for t in values for x in t]
            v = self.view(struct.pack("<%df" % len(flat), *flat), 34962)
            acc = {"bufferView": v, "componentType": 5126, "count": len(values), "type": kind}
            if kind == "VEC3":
                acc["min"] = [min(t[k] for t in values) for k in range(3)]
                acc["max"] = [max(t[k] for t in values) for k in range(3)]
            self.g["accessors"].append(acc)
        return len(self.g["accessors"]) - 1

    def mesh(self, name, geo, material):
        pos, nrm, uv, idx = geo
        prim = {"attributes": {"POSITION": self.accessor(pos, "VEC3"),
                               "NORMAL": self.accessor(nrm, "VEC3"),
                               "TEXCOORD_0": self.accessor(uv, "VEC2")},
                "indices": self.accessor(idx, "SCALAR"), "material": material}
        self.g["meshes"].append({"name": name, "primitives": [prim]})
        self.g["nodes"].append({"name": name, "mesh": len(self.g["meshes"]) - 1})
        self.g["scenes"][0]["nodes"].append(len(self.g["nodes"]) - 1)

    def material(self, m):
        self.g["materials"].append(m)
        return len(self.g["materials"]) - 1

    def camera(self, eye, yfov):
        # Looking down -z from eye, slightly down (rotation about x by -10 degrees).
        a = math.radians(-10) / 2
        self.g["cameras"] = [{"type": "perspective",
                              "perspective": {"yfov": yfov, "znear": 0.05, "aspectRatio": 1.0}}]
        self.g["nodes"].append({"name": "camera", "camera": 0, "translation": list(eye),
                                "rotation": [math.sin(a), 0, 0, math.cos(a)]})
        self.g["scenes"][0]["nodes"].append(len(self.g["nodes"]) - 1)

    def write(self, path):
        self.g["buffers"] = [{"byteLength": len(self.data), "uri":
                              "data:application/octet-stream;base64," +
                              base64.b64encode(bytes(self.data)).decode()}]
        used = sorted({k for m in self.g["materials"] for k in m.get("extensions", {})})
        if used:
            self.g["extensionsUsed"] = used
        with open(path, "w") as f:
            json.dump(self.g, f, indent=1)


LAMBERT = {"KHR_materials_specular": {"specularColorFactor": [0, 0, 0]}}


OVERHEAD_LIGHT = quad((-0.6, 2.5, 1.1), (0, 0, -1.2), (1.2, 0, 0), (0, -1, 0))


def scene(name, material, geo, light_geo=OVERHEAD_LIGHT):
    s = Gltf()
    floor = s.material({"name": "floor", "pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 1},
        "extensions": LAMBERT})
    light = s.material({"name": "light", "emissiveFactor": [1, 1, 1],
                        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 8}},
                        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                                 "metallicFactor": 0, "roughnessFactor": 1}})
    s.mesh("floor", quad((-3, 0, 3), (6, 0, 0), (0, 0, -6), (0, 1, 0)), floor)
    # Light: a 1.2 m square, by default facing down, above and in front of the object.
    s.mesh("light", light_geo, light)
    s.mesh(name, geo, s.material(material))
    s.camera((0, 1.0, 3.2), 0.6)
    return s


def main(out):
    ball = sphere(0, 0.6, 0, 0.6)
    red = [0.8, 0.1, 0.05, 1]
    scenes = {
        "clearcoat": ({"name": "coated", "pbrMetallicRoughness": {
            "baseColorFactor": red, "metallicFactor": 0, "roughnessFactor": 0.7},
            "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0,
                                                       "clearcoatRoughnessFactor": 0.15}}}, ball),
        "sheen": ({"name": "velvet", "pbrMetallicRoughness": {
            "baseColorFactor": [0.05, 0.05, 0.3, 1], "metallicFactor": 0, "roughnessFactor": 0.9},
            "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.7, 0.8],
                                                   "sheenRoughnessFactor": 0.5}}}, ball),
        "volume": ({"name": "tinted glass", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                           "KHR_materials_volume": {"thicknessFactor": 1.2,
                                                    "attenuationColor": [0.3, 0.6, 0.9],
                                                    "attenuationDistance": 2.0}}}, ball),
        # A paper screen between the light and the camera: lit from behind, it glows.
        "diffuse_transmission": ({"name": "paper", "doubleSided": True, "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.85, 0.7, 1], "metallicFactor": 0, "roughnessFactor": 1},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0},
                           "KHR_materials_diffuse_transmission": {
                               "diffuseTransmissionFactor": 0.6,
                               "diffuseTransmissionColorFactor": [1.0, 0.7, 0.4]}}},
            quad((-0.8, 0.0, 0.6), (1.6, 0, 0), (0, 1.6, 0), (0, 0, 1))),
        "anisotropy": ({"name": "brushed", "pbrMetallicRoughness": {
            "baseColorFactor": [0.95, 0.8, 0.6, 1], "metallicFactor": 1, "roughnessFactor": 0.3},
            "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.6}}}, ball),
    }
    for name, (material, geo) in scenes.items():
        # The paper screen is lit from behind (a light facing it), so that it glows.
        light = (quad((-0.6, 0.2, -0.8), (1.2, 0, 0), (0, 1.2, 0), (0, 0, 1))
                 if name == "diffuse_transmission" else OVERHEAD_LIGHT)
        scene(name, material, geo, light).write("%s/%s.gltf" % (out, name))

if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scenes/lobes")
