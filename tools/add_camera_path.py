#!/usr/bin/python3
"""Adds a smooth camera path to a glTF scene: a new perspective camera, first in the scene (so
`osr-vk` renders through it by default), moved by a glTF animation with one key per frame.

usage: add_camera_path.py IN.gltf OUT.gltf [--frames 48] [--fps 24] [--orbit] [--arc 90]

Then `osr-vk --frames 0-47 --offline shot_####.exr OUT.gltf` renders the shot.

The path comes from the scene's bounds (mesh POSITION min/max under every node transform):
- inside (default), a walk through an interior: eye height 1.6 m above the floor (at most 55%
  of the room's height), along an ellipse at 35% of the room's half-extents round its centre,
  looking across the centre at the far side, slightly down;
- --orbit, a turn round an object from outside: distance twice the bounding radius, 20 degrees
  above the centre, looking at it.
The camera sweeps --arc degrees (default 90) over the frames with eased ends (no jerk at the
first and last frame). OUT.gltf may lie in another folder: its external buffer and image URIs
are rewritten relative to it; the path's own data is embedded (a data: URI).
"""
from __future__ import annotations

import argparse
import base64
import json
import math
import os
import struct
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from arg_types import positive_float, positive_int  # noqa: E402

Vec = tuple[float, float, float]
Mat = list[list[float]]  # 4 x 4, row-major here

FLOAT = 5126


def mat_mul(a: Mat, b: Mat) -> Mat:
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def local_matrix(node: dict) -> Mat:
    """glTF's node transform: `matrix` (column-major) or T * R * S."""
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    tx, ty, tz = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    sx, sy, sz = node.get("scale", [1, 1, 1])
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    s = (sx, sy, sz)
    return [[r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], (tx, ty, tz)[i]] for i in range(3)] + \
        [[0, 0, 0, 1]]


def mesh_node_bounds(doc: dict) -> dict[int, tuple[Vec, Vec]]:
    """World bounds of each mesh node of the default scene, from its POSITION accessors'
    min/max (which glTF requires) at the eight corners, under the node's world transform."""
    bounds: dict[int, tuple[Vec, Vec]] = {}
    scenes = doc.get("scenes", [])
    roots = scenes[doc.get("scene", 0)]["nodes"] if scenes else range(len(doc.get("nodes", [])))
    stack = [(n, [[float(i == j) for j in range(4)] for i in range(4)]) for n in roots]
    while stack:
        index, parent = stack.pop()
        node = doc["nodes"][index]
        world = mat_mul(parent, local_matrix(node))
        lo, hi = [math.inf] * 3, [-math.inf] * 3
        for prim in doc["meshes"][node["mesh"]]["primitives"] if "mesh" in node else []:
            acc = doc["accessors"][prim["attributes"]["POSITION"]]
            if "min" not in acc or "max" not in acc:
                continue
            for corner in range(8):
                p = [acc["max"][k] if corner >> k & 1 else acc["min"][k] for k in range(3)]
                w = [sum(world[i][k] * p[k] for k in range(3)) + world[i][3] for i in range(3)]
                lo = [min(a, b) for a, b in zip(lo, w)]
                hi = [max(a, b) for a, b in zip(hi, w)]
        if all(math.isfinite(v) for v in lo + hi):
            bounds[index] = (tuple(lo), tuple(hi))
        stack += [(c, world) for c in node.get("children", [])]
    return bounds


def scene_bounds(doc: dict) -> tuple[Vec, Vec]:
    """World bounds of every mesh of the default scene (mesh_node_bounds)."""
    boxes = mesh_node_bounds(doc).values()
    if not boxes:
        raise ValueError("no mesh with POSITION bounds in the default scene")
    return (tuple(min(b[0][k] for b in boxes) for k in range(3)),
            tuple(max(b[1][k] for b in boxes) for k in range(3)))


def look_rotation(eye: Vec, target: Vec) -> tuple[float, float, float, float]:
    """The quaternion (x, y, z, w) turning glTF's camera (looking down -Z, +Y up) to look from
    `eye` at `target` with +Y up."""
    f = [t - e for t, e in zip(target, eye)]
    n = math.sqrt(sum(v * v for v in f))
    back = [-v / n for v in f]  # the camera's +Z
    right = [back[2], 0.0, -back[0]]  # up x back, up = +Y
    rn = math.hypot(right[0], right[2]) or 1.0
    right = [v / rn for v in right]
    up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
          back[0] * right[1] - back[1] * right[0]]
    m = [[right[0], up[0], back[0]], [right[1], up[1], back[1]], [right[2], up[2], back[2]]]
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 3
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    return (q[0], q[1], q[2], (m[k][j] - m[j][k]) / s)


def camera_keys(lo: Vec, hi: Vec, frames: int, orbit: bool, arc_deg: float
                ) -> list[tuple[Vec, tuple[float, float, float, float]]]:
    """(eye, rotation) per frame along the path."""
    centre = tuple((a + b) / 2 for a, b in zip(lo, hi))
    half = tuple((b - a) / 2 for a, b in zip(lo, hi))
    keys = []
    previous = None
    for f in range(frames):
        s = f / max(frames - 1, 1)
        eased = 0.5 - 0.5 * math.cos(math.pi * s)  # zero speed at both ends
        angle = math.radians(arc_deg) * (eased - 0.5)
        if orbit:
            radius = 2.0 * math.sqrt(sum(h * h for h in half)) or 1.0
            el = math.radians(20)
            eye = (centre[0] + radius * math.cos(el) * math.sin(angle), centre[1] + radius * math.sin(el),
                   centre[2] + radius * math.cos(el) * math.cos(angle))
            target = centre
        else:
            height = min(1.6, 0.55 * (hi[1] - lo[1]))
            y = lo[1] + height
            eye = (centre[0] + 0.35 * half[0] * math.sin(angle), y,
                   centre[2] + 0.35 * half[2] * math.cos(angle))
            # Across the centre to the far side, a little below eye height.
            target = (2 * centre[0] - eye[0], y - 0.15 * height, 2 * centre[2] - eye[2])
        q = look_rotation(eye, target)
        if previous and sum(a * b for a, b in zip(q, previous)) < 0:
            q = tuple(-v for v in q)  # the same rotation, on the short arc from the last key
        previous = q
        keys.append((eye, q))
    return keys


def rebase_uri(uri: str, src_dir: Path, out_dir: Path) -> str:
    if uri.startswith("data:") or "://" in uri:
        return uri
    return os.path.relpath(src_dir / uri, out_dir).replace(os.sep, "/")


def rebase_uris(doc: dict, src: Path, out: Path) -> None:
    """Makes the relative URIs of `doc`'s buffers and images, read from file `src`, point at the
    same files from file `out`."""
    src_dir, out_dir = src.resolve().parent, out.resolve().parent
    for item in doc.get("buffers", []) + doc.get("images", []):
        if "uri" in item:
            item["uri"] = rebase_uri(item["uri"], src_dir, out_dir)


def add_animation(doc: dict, name: str, times: list[float],
                  tracks: list[tuple[int, str, list[tuple[float, ...]]]]) -> None:
    """Appends a glTF animation `name` with one LINEAR channel per (node, path, values) track,
    every track keyed at `times` (seconds); its data goes into a new embedded buffer."""
    blob = bytearray()
    views: list[dict] = []
    accessors: list[dict] = []
    buffer = len(doc.setdefault("buffers", []))

    def accessor(values: list[tuple[float, ...]], kind: str) -> int:
        data = b"".join(struct.pack("<%df" % len(v), *v) for v in values)
        views.append({"buffer": buffer, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        acc: dict[str, Any] = {"bufferView": len(doc.setdefault("bufferViews", [])) + len(views) - 1,
                               "componentType": FLOAT, "count": len(values), "type": kind}
        if kind == "SCALAR":  # animation inputs must carry min and max
            acc["min"], acc["max"] = [min(v[0] for v in values)], [max(v[0] for v in values)]
        accessors.append(acc)
        return len(doc.setdefault("accessors", [])) + len(accessors) - 1

    t_in = accessor([(t,) for t in times], "SCALAR")
    outputs = [accessor(values, "VEC%d" % len(values[0])) for _, _, values in tracks]
    doc["buffers"].append({"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                           + base64.b64encode(bytes(blob)).decode()})
    doc["bufferViews"] += views
    doc["accessors"] += accessors
    doc.setdefault("animations", []).append({
        "name": name,
        "samplers": [{"input": t_in, "output": out, "interpolation": "LINEAR"} for out in outputs],
        "channels": [{"sampler": i, "target": {"node": node, "path": path}}
                     for i, (node, path, _) in enumerate(tracks)]})


def add_camera_path(doc: dict, frames: int, fps: float, orbit: bool, arc: float,
                    yfov: float) -> dict:
    lo, hi = scene_bounds(doc)
    keys = camera_keys(lo, hi, frames, orbit, arc)
    times = [f / fps for f in range(frames)]
    camera = len(doc.setdefault("cameras", []))
    doc["cameras"].append({"type": "perspective", "name": "camera_path",
                           "perspective": {"yfov": yfov, "znear": 0.05}})
    node = len(doc.setdefault("nodes", []))
    doc["nodes"].append({"name": "camera_path", "camera": camera, "translation": list(keys[0][0]),
                         "rotation": list(keys[0][1])})
    if not doc.get("scenes"):
        doc["scenes"], doc["scene"] = [{"nodes": []}], 0
    doc["scenes"][doc.get("scene", 0)]["nodes"].insert(0, node)  # the first camera osr-vk finds
    add_animation(doc, "camera_path", times, [(node, "translation", [k[0] for k in keys]),
                                              (node, "rotation", [k[1] for k in keys])])
    return doc


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", type=Path, help="the scene (.gltf)")
    p.add_argument("output", type=Path, help="the scene with the camera path (.gltf)")
    p.add_argument("--frames", type=positive_int, default=48, help="frames, one key each (48)")
    p.add_argument("--fps", type=positive_float, default=24.0, help="frames per second (24)")
    p.add_argument("--orbit", action="store_true", help="round the scene from outside")
    p.add_argument("--arc", type=positive_float, default=90.0, help="degrees swept (90)")
    p.add_argument("--yfov", type=positive_float, default=1.0, help="vertical field of view, radians (1.0)")
    args = p.parse_args(argv)
    if args.input.suffix.lower() != ".gltf" or args.output.suffix.lower() != ".gltf":
        p.error("IN and OUT must be .gltf files (JSON glTF; convert a .glb first)")
    if args.yfov >= math.pi:
        p.error("--yfov must be below pi")
    try:
        doc = json.loads(args.input.read_text())
    except (OSError, ValueError) as e:
        print(f"add_camera_path.py: {args.input}: {e}", file=sys.stderr)
        return 2
    rebase_uris(doc, args.input, args.output)
    try:
        add_camera_path(doc, args.frames, args.fps, args.orbit, args.arc, args.yfov)
    except (KeyError, IndexError, TypeError, ValueError) as e:
        print(f"add_camera_path.py: {args.input}: not a scene it can frame ({e})", file=sys.stderr)
        return 2
    args.output.write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
