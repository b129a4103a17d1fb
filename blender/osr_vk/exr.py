# OpenEXR in pure Python + numpy: Blender's Python API has no way to read one layer of a
# multi-layer EXR into arrays, and osr-vk writes its passes as layers of one file
# (src/image/image_io.cpp: default R, G, B plus "direct.R", ..., "depth.Z"). Reads single-part
# scanline files with NONE, RLE, ZIPS or ZIP compression (what OpenEXR writers use by default;
# osr-vk writes ZIP), HALF / FLOAT / UINT channels. Writes uncompressed float RGB files (the
# constant world colour handed to osr-vk as --env).
import struct
import zlib

import numpy as np

_MAGIC = 20000630
_NONE, _RLE, _ZIPS, _ZIP = 0, 1, 2, 3
_LINES_PER_CHUNK = {_NONE: 1, _RLE: 1, _ZIPS: 1, _ZIP: 16}
_COMPRESSION_NAMES = {4: "PIZ", 5: "PXR24", 6: "B44", 7: "B44A", 8: "DWAA", 9: "DWAB"}
# OpenEXR pixel types: UINT, HALF, FLOAT.
_DTYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}


class ExrError(Exception):
    pass


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("utf-8", "replace"), end + 1


def _parse_header(data):
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != _MAGIC:
        raise ExrError("not an OpenEXR file")
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0x200:
        raise ExrError("tiled OpenEXR files are not supported")
    if flags & 0x1000 or flags & 0x800:
        raise ExrError("multi-part or deep OpenEXR files are not supported")
    pos, attrs = 8, {}
    while data[pos] != 0:
        name, pos = _cstring(data, pos)
        kind, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        attrs[name] = (kind, data[pos:pos + size])
        pos += size
    return attrs, pos + 1


def _channels(raw):
    out, pos = [], 0
    while raw[pos] != 0:
        name, pos = _cstring(raw, pos)
        pixel_type, _, _, xs, ys = struct.unpack_from("<iB3sii", raw, pos)
        pos += 16
        if pixel_type not in _DTYPES:
            raise ExrError("channel %s has unknown pixel type %d" % (name, pixel_type))
        if xs != 1 or ys != 1:
            raise ExrError("channel %s is subsampled" % name)
        out.append((name, _DTYPES[pixel_type]))
    return out


def _unrle(src, size):
    out, i = bytearray(), 0
    while i < len(src):
        count = struct.unpack_from("b", src, i)[0]
        i += 1
        if count < 0:
            out += src[i:i - count]
            i -= count
        else:
            out += src[i:i + 1] * (count + 1)
            i += 1
    if len(out) != size:
        raise ExrError("corrupt RLE data")
    return bytes(out)


def _unpredict(raw):
    # Undo OpenEXR's byte predictor and its even/odd byte split (ImfZip.cpp).
    t = np.frombuffer(raw, np.uint8).astype(np.int64)
    t = (np.cumsum(t) - 128 * np.arange(t.size)) & 0xFF
    t = t.astype(np.uint8)
    out = np.empty_like(t)
    half = (t.size + 1) // 2
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def read_layers(path):
    """Returns (width, height, {channel name: float32 array [height, width], top row first})."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise ExrError("%s: cannot read (%s)" % (path, e.strerror))
    try:
        return _decode(data)
    except ExrError as e:
        raise ExrError("%s: %s" % (path, e))
    except (struct.error, ValueError, IndexError, zlib.error) as e:
        raise ExrError("%s: corrupt OpenEXR file (%s)" % (path, e))


def _decode(data):
    attrs, pos = _parse_header(data)
    for required in ("channels", "compression", "dataWindow"):
        if required not in attrs:
            raise ExrError("header has no %s" % required)
    channels = _channels(attrs["channels"][1])
    compression = attrs["compression"][1][0]
    if compression not in _LINES_PER_CHUNK:
        raise ExrError("%s compression is not supported (NONE, RLE, ZIPS, ZIP are)"
                       % _COMPRESSION_NAMES.get(compression, str(compression)))
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    if width <= 0 or height <= 0:
        raise ExrError("empty data window")
    lines = _LINES_PER_CHUNK[compression]
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from("<%dQ" % chunks, data, pos)
    planes = {name: np.empty((height, width), np.float32) for name, _ in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        block = data[offset + 8:offset + 8 + size]
        row0 = y - ymin
        rows = min(lines, height - row0)
        if row0 < 0 or rows <= 0:
            raise ExrError("chunk for line %d outside the data window" % y)
        expected = rows * width * sum(dt.itemsize for _, dt in channels)
        if size < expected:  # a chunk that did not shrink is stored raw
            if compression in (_ZIP, _ZIPS):
                block = _unpredict(zlib.decompress(block))
            elif compression == _RLE:
                block = _unpredict(_unrle(block, expected))
        if len(block) != expected:
            raise ExrError("chunk for line %d has %d bytes, expected %d" % (y, len(block), expected))
        at = 0
        for r in range(rows):  # per line: each channel's samples in turn
            for name, dt in channels:
                n = width * dt.itemsize
                planes[name][row0 + r] = np.frombuffer(block, dt, width, at)
                at += n
    return width, height, planes


def write_rgb(path, rgb):
    """Writes a float32 array [height, width, 3] (top row first) as an uncompressed EXR."""
    rgb = np.ascontiguousarray(rgb, np.float32)
    height, width = rgb.shape[:2]

    def attr(name, kind, payload):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) + payload

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3sii", 2, 0, b"\0\0\0", 1, 1)
                      for c in "BGR") + b"\0"
    window = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (struct.pack("<iI", _MAGIC, 2) + attr("channels", "chlist", chlist)
              + attr("compression", "compression", bytes([_NONE]))
              + attr("dataWindow", "box2i", window) + attr("displayWindow", "box2i", window)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1))
              + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    line_bytes = 3 * 4 * width
    first = len(header) + 8 * height
    table = struct.pack("<%dQ" % height, *[first + y * (8 + line_bytes) for y in range(height)])
    body = bytearray()
    for y in range(height):
        body += struct.pack("<ii", y, line_bytes)
        for c in (2, 1, 0):  # channels in name order: B, G, R
            body += rgb[y, :, c].tobytes()
    with open(path, "wb") as f:
        f.write(header + table + bytes(body))
