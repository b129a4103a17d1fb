#!/usr/bin/env python3
"""Writes a small studio environment (equirectangular float OpenEXR, v = 0 at the top, +Y up):
a dim grey dome, a darker ground and two bright softboxes high on either side, so glossy coats,
sheen and glass show highlights that a uniform sky does not give (docs/pathtracer.md renders the
Khronos sample models with it):

    /usr/bin/python3 tools/studio_env.py OUT.exr [--width 256]
"""
import argparse

import numpy as np

from exr_file import write_raw

FLOAT = 2  # OpenEXR pixel type


def studio(width: int) -> np.ndarray:
    height = width // 2
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    elevation = (0.5 - v)[:, None] * np.pi  # +pi/2 at the top
    azimuth = (u[None, :] - 0.5) * 2.0 * np.pi
    sky = np.where(elevation > 0, 0.25 + 0.15 * np.sin(elevation), 0.08)
    rgb = np.repeat(sky[..., None], 3, axis=-1) * np.ones((1, width, 1))
    for centre in (-1.0, 1.2):  # azimuth of each softbox, radians
        box = (np.abs(azimuth - centre) < 0.35) & (np.abs(elevation - 0.6) < 0.25)
        rgb[box] = 12.0
    return rgb.astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--width", type=int, default=256)
    args = parser.parse_args()
    if args.width < 8 or args.width % 2:
        parser.error(f"--width {args.width}: an even number of at least 8")
    rgb = studio(args.width)
    write_raw(args.out, {c: (FLOAT, rgb[..., i].view(np.uint32)) for i, c in enumerate("RGB")})


if __name__ == "__main__":
    main()
