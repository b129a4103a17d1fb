#!/usr/bin/env python3
"""Writes a .glb of one displaced sphere of at least N triangles, with a camera, for trying
osr-vk at scale (issue 13: 10M triangles load, build and render on lavapipe):

    tools/make_large_mesh.py /tmp/sphere10m.glb --triangles 10000000
    osr-vk --mode path --spp 4 --width 256 --height 256 --offline out.exr --png out.png /tmp/sphere10m.glb

The sphere is the one `osr-bench bvh --triangles N` builds (src/bvh/synthetic_mesh.cpp
makeSphere, bumps 0.15), as rings x 2 rings quads. Needs numpy (the list-based writer of
gltf_build.py is too slow for tens of millions of elements).
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from gltf_build import FLOAT, UINT, Gltf


def sphere(triangles: int, bumps: float = 0.15) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, normals (float32, V x 3) and indices (uint32, T x 3) of the displaced sphere."""
    rings = math.ceil(math.sqrt(triangles / 4.0))
    segments = 2 * rings
    theta = (np.pi * np.arange(rings + 1) / rings)[:, None]
    phi = (2.0 * np.pi * np.arange(segments + 1) / segments)[None, :]
    shape = (rings + 1, segments + 1)
    n = np.stack([np.sin(theta) * np.cos(phi), np.broadcast_to(np.cos(theta), shape), np.sin(theta) * np.sin(phi)],
                 axis=-1).reshape(-1, 3)
    h = 1.0 + bumps * np.sin(7.0 * phi) * np.sin(5.0 * theta) * np.sin(3.0 * phi + theta)
    positions = (n * h.reshape(-1, 1)).astype(np.float32)
    r, s = np.meshgrid(np.arange(rings, dtype=np.uint32), np.arange(segments, dtype=np.uint32), indexing="ij")
    i0 = (r * (segments + 1) + s).ravel()
    i1, i2 = i0 + 1, i0 + segments + 1
    i3 = i2 + 1
    indices = np.empty((2 * i0.size, 3), dtype=np.uint32)
    indices[0::2] = np.stack([i0, i2, i1], axis=1)
    indices[1::2] = np.stack([i1, i2, i3], axis=1)
    return positions, n.astype(np.float32), indices


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", type=Path, help="output .glb")
    parser.add_argument("--triangles", type=int, default=10_000_000, help="at least this many (default 10M)")
    args = parser.parse_args()
    if args.out.suffix != ".glb":
        parser.error(f"{args.out}: the output must end in .glb")
    if not 1 <= args.triangles <= 1 << 27:
        parser.error("--triangles must be in 1..134217728")
    positions, normals, indices = sphere(args.triangles)
    g = Gltf("osr-vk tools/make_large_mesh.py")

    def accessor(data: np.ndarray, kind: str, component: int, bounds: bool = False) -> int:
        acc = {"bufferView": g.view(data.tobytes()), "componentType": component, "count": len(data), "type": kind}
        if bounds:
            acc["min"] = data.min(axis=0).tolist()
            acc["max"] = data.max(axis=0).tolist()
        return g.add("accessors", acc)

    prim = {"attributes": {"POSITION": accessor(positions, "VEC3", FLOAT, True),
                           "NORMAL": accessor(normals, "VEC3", FLOAT)},
            "indices": accessor(indices.ravel(), "SCALAR", UINT),
            "material": g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1.0],
                                                                     "metallicFactor": 0.0, "roughnessFactor": 0.6}})}
    g.node(mesh=g.add("meshes", {"primitives": [prim]}))
    # Outside, looking down at the bumps (rotation: a lookAt from (0.4, 0.9, 3.0) to the origin).
    eye = np.array([0.4, 0.9, 3.0])
    back = eye / np.linalg.norm(eye)
    right = np.cross([0.0, 1.0, 0.0], back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    m = np.stack([right, up, back], axis=1)  # columns: camera x, y, z in world space
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2.0
    q = [(m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w), (m[1, 0] - m[0, 1]) / (4 * w), w]
    g.node(camera=g.add("cameras", {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}),
           translation=eye.tolist(), rotation=[float(c) for c in q])
    g.glb(args.out)
    print(f"{args.out}: {len(indices)} triangles, {len(positions)} vertices, {args.out.stat().st_size >> 20} MiB")


if __name__ == "__main__":
    main()
