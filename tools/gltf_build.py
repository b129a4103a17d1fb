"""glTF 2.0 writing for osr-vk's Python tools: one buffer, the JSON that views it, and a minimal
PNG encoder for textures. Shared by make_scene_test_data.py (the loader's test files) and
make_interiors.py (procedural training scenes).
"""
from __future__ import annotations

import base64
import json
import math
import struct
import zlib
from pathlib import Path
from typing import Any

FLOAT, BYTE, UBYTE, SHORT, USHORT, UINT = 5126, 5120, 5121, 5122, 5123, 5125
REPEAT, CLAMP, MIRROR = 10497, 33071, 33648
NEAREST = 9728


def png(width: int, height: int, texels: list[tuple[int, int, int, int]], bits: int = 8) -> bytes:
    """Minimal RGBA PNG encoder, 8 or 16 bits per channel (filter 0 on every row)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    fmt = ">4B" if bits == 8 else ">4H"
    rows = b""
    for y in range(height):
        rows += b"\x00" + b"".join(struct.pack(fmt, *texels[y * width + x]) for x in range(width))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bits, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64," + base64.b64encode(data).decode()


class Gltf:
    """Accumulates one buffer and the JSON that views it."""

    def __init__(self, generator: str = "osr-vk tools/gltf_build.py") -> None:
        self.bin = bytearray()
        self.doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": generator},
                                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                                    "accessors": [], "bufferViews": [], "buffers": []}

    def view(self, data: bytes) -> int:
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values: list, kind: str, component: int = FLOAT, normalized: bool = False,
                 stride: int = 0) -> int:
        fmt = {FLOAT: "f", BYTE: "b", UBYTE: "B", SHORT: "h", USHORT: "H", UINT: "I"}[component]
        flat = [c for v in values for c in (v if isinstance(v, (list, tuple)) else [v])]
        data = struct.pack("<" + fmt * len(flat), *flat)
        if stride:  # interleave padding: each element starts `stride` bytes after the last
            size = len(data) // len(values)
            data = b"".join(data[i * size:(i + 1) * size] + b"\xee" * (stride - size) for i in range(len(values)))
        acc: dict[str, Any] = {"bufferView": self.view(data),
                               "componentType": component, "count": len(values), "type": kind}
        if stride:
            self.doc["bufferViews"][-1]["byteStride"] = stride
        if normalized:
            acc["normalized"] = True
        if kind == "VEC3" and component == FLOAT and all(map(math.isfinite, flat)):
            acc["min"] = [min(v[i] for v in values) for i in range(3)]
            acc["max"] = [max(v[i] for v in values) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, positions: list, indices: list | None = None, normals: list | None = None,
             uvs: list | None = None, material: int | None = None, index_type: int = USHORT,
             mode: int | None = None) -> int:
        prim: dict[str, Any] = {"attributes": {"POSITION": self.accessor(positions, "VEC3")}}
        if normals is not None:
            prim["attributes"]["NORMAL"] = self.accessor(normals, "VEC3")
        if uvs is not None:
            prim["attributes"]["TEXCOORD_0"] = self.accessor(uvs, "VEC2")
        if indices is not None:
            prim["indices"] = self.accessor(indices, "SCALAR", index_type)
        if material is not None:
            prim["material"] = material
        if mode is not None:
            prim["mode"] = mode
        self.doc["meshes"].append({"primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def node(self, root: bool = True, **fields: Any) -> int:
        self.doc["nodes"].append(fields)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def animate(self, node: int, path: str, times: list[float], values: list,
                interpolation: str = "LINEAR", animation: int = 0) -> None:
        """Adds a channel moving `node`'s `path` (translation, rotation, scale) to animation
        `animation` (made when missing); CUBICSPLINE values are (in-tangent, value,
        out-tangent) per key."""
        anims = self.doc.setdefault("animations", [])
        while len(anims) <= animation:
            anims.append({"channels": [], "samplers": []})
        kind = {"translation": "VEC3", "rotation": "VEC4", "scale": "VEC3", "weights": "SCALAR"}[path]
        anim = anims[animation]
        anim["samplers"].append({"input": self.accessor(list(times), "SCALAR"),
                                 "output": self.accessor(list(values), kind),
                                 "interpolation": interpolation})
        anim["channels"].append({"sampler": len(anim["samplers"]) - 1,
                                 "target": {"node": node, "path": path}})

    def add(self, key: str, item: dict) -> int:
        self.doc.setdefault(key, []).append(item)
        return len(self.doc[key]) - 1

    def gltf(self, path: Path, external_bin: str | None = None) -> None:
        if external_bin:
            (path.parent / external_bin).write_bytes(bytes(self.bin))
            uri = external_bin
        else:
            uri = data_uri(bytes(self.bin), "application/octet-stream")
        self.doc["buffers"] = [{"byteLength": len(self.bin), "uri": uri}]
        path.write_text(json.dumps(self.doc, indent=1) + "\n")

    def glb(self, path: Path) -> None:
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.bin)}]
        text = json.dumps(self.doc).encode()
        text += b" " * (-len(text) % 4)
        body = (struct.pack("<II", len(text), 0x4E4F534A) + text
                + struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin))
        path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
