#!/usr/bin/python3
"""Moves one mesh node of a glTF scene: a glTF animation that slides it by a fixed offset.

usage: add_object_path.py IN.gltf OUT.gltf --node N --move DX DY DZ [--frames 48] [--fps 24]
       add_object_path.py IN.gltf --list

The node's translation goes from its rest value to rest + (DX, DY, DZ) (world units, in its
parent's frame) over the frames with eased ends, one LINEAR key per frame; its rotation and
scale stay. `--list` prints each mesh node of the default scene with its world bounds, to
choose N. A shot with a moving object for `osr-vk --frames` (docs/animation.md):

    tools/make_interiors.py /tmp/int --seeds 3
    tools/add_object_path.py /tmp/int/3/scene.gltf --list
    tools/add_object_path.py /tmp/int/3/scene.gltf /tmp/moving.gltf --node 7 --move 1 0 0

OUT.gltf may lie in another folder: its external buffer and image URIs are rewritten relative
to it; the path's own data is embedded (a data: URI).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from add_camera_path import add_animation, mesh_node_bounds, rebase_uris  # noqa: E402
from arg_types import positive_float, positive_int  # noqa: E402


def add_object_path(doc: dict, node: int, move: tuple[float, float, float], frames: int,
                    fps: float) -> dict:
    """Animates `node`'s translation from its rest value by `move` over `frames` keys."""
    if node not in mesh_node_bounds(doc):
        raise ValueError(f"node {node} is not a mesh node of the default scene (--list)")
    target = doc["nodes"][node]
    if "matrix" in target:
        raise ValueError(f"node {node} has a matrix, which glTF does not animate")
    rest = target.get("translation", [0.0, 0.0, 0.0])
    keys = []
    for f in range(frames):
        s = f / max(frames - 1, 1)
        eased = 0.5 - 0.5 * math.cos(math.pi * s)  # zero speed at both ends
        keys.append(tuple(r + eased * m for r, m in zip(rest, move)))
    add_animation(doc, f"object_path_{node}", [f / fps for f in range(frames)],
                  [(node, "translation", keys)])
    return doc


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", type=Path, help="the scene (.gltf)")
    p.add_argument("output", type=Path, nargs="?", help="the scene with the moving node (.gltf)")
    p.add_argument("--list", action="store_true", help="print the mesh nodes and their bounds")
    p.add_argument("--node", type=int, help="the mesh node to move (its index)")
    p.add_argument("--move", type=float, nargs=3, metavar=("DX", "DY", "DZ"),
                   help="the offset at the last frame")
    p.add_argument("--frames", type=positive_int, default=48, help="frames, one key each (48)")
    p.add_argument("--fps", type=positive_float, default=24.0, help="frames per second (24)")
    args = p.parse_args(argv)
    if args.input.suffix.lower() != ".gltf":
        p.error("IN must be a .gltf file (JSON glTF; convert a .glb first)")
    if not args.list:
        if args.output is None or args.output.suffix.lower() != ".gltf":
            p.error("OUT must be a .gltf file")
        if args.node is None or args.move is None:
            p.error("--node and --move are required (--list shows the nodes)")
        if not all(math.isfinite(v) for v in args.move):
            p.error("--move: expects finite numbers")
    try:
        doc = json.loads(args.input.read_text())
    except (OSError, ValueError) as e:
        print(f"add_object_path.py: {args.input}: {e}", file=sys.stderr)
        return 2
    if args.list:
        for node, (lo, hi) in sorted(mesh_node_bounds(doc).items()):
            name = doc["nodes"][node].get("name", "")
            print(f"{node} {name!r} bounds ({lo[0]:.3f}, {lo[1]:.3f}, {lo[2]:.3f}) - "
                  f"({hi[0]:.3f}, {hi[1]:.3f}, {hi[2]:.3f})")
        return 0
    rebase_uris(doc, args.input, args.output)
    try:
        add_object_path(doc, args.node, tuple(args.move), args.frames, args.fps)
    except (KeyError, IndexError, TypeError, ValueError) as e:
        print(f"add_object_path.py: {args.input}: {e}", file=sys.stderr)
        return 2
    args.output.write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
