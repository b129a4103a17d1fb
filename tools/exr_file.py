"""The OpenEXR files osr-vk writes (single-part scanline images, half or float channels, ZIP
compressed), read and written with numpy and zlib: Debian 12 packages no OpenEXR binding for
Python, and tools/osr_farm.py needs only this much of the format to check a frame or tile
(read_header / check_complete) and to paste tiles into one image (read_raw / write_raw).

Channels are handled as raw bits (uint16 for half, uint32 for float), so tiles pasted together
keep every pixel's value exactly. Format: https://openexr.com/en/latest/OpenEXRFileLayout.html
"""
from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import numpy as np

MAGIC = 20000630
PIXEL_TYPES = {0: ("UINT", np.uint32), 1: ("HALF", np.uint16), 2: ("FLOAT", np.uint32)}
NO_COMPRESSION, ZIPS_COMPRESSION, ZIP_COMPRESSION = 0, 2, 3
LINES_PER_CHUNK = {NO_COMPRESSION: 1, ZIPS_COMPRESSION: 1, ZIP_COMPRESSION: 16}


class ExrError(Exception):
    """A file that is not a complete OpenEXR image of the kind osr-vk writes."""


def _cstring(data: bytes, pos: int) -> tuple[str, int]:
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def read_header(path: str | Path) -> dict:
    """Parses the header: width, height, channels [(name, pixel type)], compression, and where
    the chunk offset table starts. Raises ExrError for anything else than a single-part
    scanline file with a compression this module reads."""
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrError(f"{path}: not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0xFF != 2 or version & 0x1E00:  # tiled, long names, deep or multi-part
        raise ExrError(f"{path}: not a single-part scanline OpenEXR file")
    pos, attrs = 8, {}
    try:
        while True:
            name, pos = _cstring(data, pos)
            if not name:
                break
            kind, pos = _cstring(data, pos)
            size = struct.unpack_from("<i", data, pos)[0]
            attrs[name] = (kind, data[pos + 4:pos + 4 + size])
            pos += 4 + size
            if pos > len(data):
                raise ExrError(f"{path}: truncated header")
    except (ValueError, struct.error) as e:
        raise ExrError(f"{path}: truncated header") from e
    for required in ("channels", "compression", "dataWindow"):
        if required not in attrs:
            raise ExrError(f"{path}: header without {required}")
    channels, raw, p = [], attrs["channels"][1], 0
    while raw[p:p + 1] != b"\0":
        cname, p = _cstring(raw, p)
        ptype = struct.unpack_from("<i", raw, p)[0]
        if ptype not in PIXEL_TYPES or struct.unpack_from("<ii", raw, p + 8) != (1, 1):
            raise ExrError(f"{path}: channel {cname}: unsupported pixel type or sampling")
        channels.append((cname, ptype))
        p += 16
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    compression = attrs["compression"][1][0]
    if compression not in LINES_PER_CHUNK:
        raise ExrError(f"{path}: compression {compression} is not NONE, ZIPS or ZIP")
    return {"width": x1 - x0 + 1, "height": y1 - y0 + 1, "y0": y0, "channels": channels,
            "compression": compression, "table": pos}


def _chunk_table(path: str | Path, h: dict) -> tuple[bytes, list[int]]:
    data = Path(path).read_bytes()
    lines = LINES_PER_CHUNK[h["compression"]]
    count = (h["height"] + lines - 1) // lines
    end = h["table"] + 8 * count
    if len(data) < end:
        raise ExrError(f"{path}: truncated (offset table)")
    offsets = list(struct.unpack_from(f"<{count}Q", data, h["table"]))
    for off in offsets:
        if off < end or off + 8 > len(data) or off + 8 + struct.unpack_from("<i", data, off + 4)[0] > len(data):
            raise ExrError(f"{path}: truncated (a chunk lies past the end of the file)")
    return data, offsets


def check_complete(path: str | Path, width: int | None = None, height: int | None = None,
                   channels: list[str] | None = None) -> dict:
    """The header of a complete file (every chunk the offset table lists is inside it) of the
    given size and with at least the given channels; ExrError otherwise."""
    h = read_header(path)
    if (width, height) != (None, None) and (h["width"], h["height"]) != (width, height):
        raise ExrError(f"{path}: {h['width']}x{h['height']}, expected {width}x{height}")
    missing = set(channels or []) - {c for c, _ in h["channels"]}
    if missing:
        raise ExrError(f"{path}: no channel {sorted(missing)[0]}")
    _chunk_table(path, h)
    return h


def read_raw(path: str | Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The header and each channel's pixels as raw bits, [height, width] arrays."""
    h = check_complete(path)
    data, offsets = _chunk_table(path, h)
    w, height = h["width"], h["height"]
    lines = LINES_PER_CHUNK[h["compression"]]
    sizes = [np.dtype(PIXEL_TYPES[t][1]).itemsize for _, t in h["channels"]]
    out = {c: np.zeros((height, w), PIXEL_TYPES[t][1]) for c, t in h["channels"]}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        row = y - h["y0"]
        n = min(lines, height - row)
        expected = n * w * sum(sizes)
        block = data[off + 8:off + 8 + size]
        if h["compression"] != NO_COMPRESSION and size < expected:
            block = _unzip(block, expected)
        if len(block) != expected:
            raise ExrError(f"{path}: chunk at line {y} has {len(block)} bytes, expected {expected}")
        pos = 0
        for line in range(n):
            for (c, t), s in zip(h["channels"], sizes):
                out[c][row + line] = np.frombuffer(block, PIXEL_TYPES[t][1], w, pos)
                pos += w * s
    return h, out


def write_raw(path: str | Path, channels: dict[str, tuple[int, np.ndarray]]) -> None:
    """Writes a ZIP-compressed scanline file of channels {name: (pixel type, [h, w] raw bits)}
    through a temporary name, renamed when complete: a half-written file never stands."""
    names = sorted(channels)
    height, w = channels[names[0]][1].shape
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", channels[c][0], 0, 1, 1) for c in names) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, height - 1)

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    header = (struct.pack("<iI", MAGIC, 2) + attr("channels", "chlist", chlist)
              + attr("compression", "compression", bytes([ZIP_COMPRESSION]))
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    lines = LINES_PER_CHUNK[ZIP_COMPRESSION]
    count = (height + lines - 1) // lines
    chunks = []
    for y in range(0, height, lines):
        rows = [channels[c][1][y:y + lines] for c in names]
        raw = b"".join(r[line].astype(r.dtype.newbyteorder("<")).tobytes()
                       for line in range(rows[0].shape[0]) for r in rows)
        packed = _zip(raw)
        block = packed if len(packed) < len(raw) else raw
        chunks.append(struct.pack("<ii", y, len(block)) + block)
    offsets, pos = [], len(header) + 8 * count
    for c in chunks:
        offsets.append(pos)
        pos += len(c)
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(header + struct.pack(f"<{count}Q", *offsets) + b"".join(chunks))
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def _unzip(block: bytes, expected: int) -> bytes:
    t = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int64)
    if t.size != expected:
        raise ExrError(f"ZIP chunk of {t.size} bytes, expected {expected}")
    t[1:] -= 128  # undo the predictor: each byte was stored as the difference to the last + 128
    t = (np.cumsum(t) & 0xFF).astype(np.uint8)
    out = np.empty_like(t)
    half = (t.size + 1) // 2  # undo the interleave: even bytes first, then odd ones
    out[0::2], out[1::2] = t[:half], t[half:]
    return out.tobytes()


def _zip(raw: bytes) -> bytes:
    b = np.frombuffer(raw, np.uint8)
    t = np.concatenate([b[0::2], b[1::2]]).astype(np.int64)
    p = t.copy()
    p[1:] = (t[1:] - t[:-1] + 128) & 0xFF
    return zlib.compress(p.astype(np.uint8).tobytes(), 6)


def to_float(ptype: int, bits: np.ndarray) -> np.ndarray:
    """A channel's raw bits as float32 values."""
    return bits.view(np.float16).astype(np.float32) if ptype == 1 else bits.view(np.float32)


def read_rgb(path: str | Path, layer: str = "") -> np.ndarray:
    """The R, G, B channels (of `layer`, as osr-vk names them: noisy.R, ...) as an H x W x 3
    float32 array; ExrError names a missing channel."""
    h, raw = read_raw(path)
    types = dict(h["channels"])
    names = [f"{layer}.{c}" if layer else c for c in "RGB"]
    missing = next((n for n in names if n not in types), None)
    if missing is not None:
        raise ExrError(f"{path}: no channel {missing}")
    return np.stack([to_float(types[n], raw[n]) for n in names], -1)
