"""Minimal OpenEXR scanline reading (uncompressed or ZIP) and writing (ZIP), numpy only.

Blender's Python has no OpenEXR module; the reference scripts read Blender's multilayer
render output with `read_exr` and write Glint's reference files with `write_exr`.
"""

import struct
import zlib

import numpy as np

PIXEL_TYPES = {0: np.uint32, 1: np.float16, 2: np.float32}
NO_COMPRESSION, ZIPS_COMPRESSION, ZIP_COMPRESSION = 0, 2, 3
LINES_PER_CHUNK = {NO_COMPRESSION: 1, ZIPS_COMPRESSION: 1, ZIP_COMPRESSION: 16}


def _zip_decode(data, size):
    raw = np.frombuffer(zlib.decompress(data), dtype=np.uint8)
    assert raw.size == size
    t = ((np.cumsum(raw.astype(np.int64) - 128) + 128) & 255).astype(np.uint8)
    half = (size + 1) // 2
    out = np.empty(size, dtype=np.uint8)
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def _zip_encode(raw):
    b = np.frombuffer(raw, dtype=np.uint8)
    t = np.concatenate([b[0::2], b[1::2]]).astype(np.int64)
    d = np.empty_like(t)
    d[0] = t[0]
    d[1:] = (t[1:] - t[:-1] + 128 + 256) & 255
    return zlib.compress(d.astype(np.uint8).tobytes(), 9)


def _header(data):
    assert struct.unpack_from("<I", data, 0)[0] == 20000630, "not an OpenEXR file"
    flags = struct.unpack_from("<I", data, 4)[0]
    assert flags & 0xFF == 2 and flags & 0x1A00 == 0, "tiled, multi-part or deep EXR"
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1 : tend].decode()
        (size,) = struct.unpack_from("<i", data, tend + 1)
        value = data[tend + 5 : tend + 5 + size]
        attrs[name] = (kind, value)
        pos = tend + 5 + size
    return attrs, pos + 1


def _channels(value):
    channels, pos = [], 0
    while value[pos] != 0:
        end = value.index(b"\0", pos)
        name = value[pos:end].decode()
        pixel_type, _linear, xs, ys = struct.unpack_from("<iB3xii", value, end + 1)
        assert xs == 1 and ys == 1, "subsampled channel"
        channels.append((name, pixel_type))
        pos = end + 17
    return channels


def read_exr(path):
    """{channel name: float32 array (height, width)} of a scanline EXR."""
    with open(path, "rb") as f:
        data = f.read()
    attrs, pos = _header(data)
    channels = _channels(attrs["channels"][1])
    compression = attrs["compression"][1][0]
    assert compression in LINES_PER_CHUNK, f"compression {compression} not supported"
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines = LINES_PER_CHUNK[compression]
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    out = {name: np.zeros((height, width), np.float32) for name, _ in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        block = data[offset + 8 : offset + 8 + size]
        n = min(lines, y1 + 1 - y)
        raw_size = (
            n * width * sum(np.dtype(PIXEL_TYPES[t]).itemsize for _, t in channels)
        )
        if size < raw_size:
            block = _zip_decode(block, raw_size)
        p = 0
        for row in range(n):
            for name, t in channels:
                dtype = np.dtype(PIXEL_TYPES[t]).newbyteorder("<")
                values = np.frombuffer(block, dtype=dtype, count=width, offset=p)
                out[name][y - y0 + row] = values.astype(np.float32)
                p += width * dtype.itemsize
    return out


def _attribute(name, kind, value):
    return (
        name.encode()
        + b"\0"
        + kind.encode()
        + b"\0"
        + struct.pack("<i", len(value))
        + value
    )


def write_exr(path, channels, attributes=None):
    """Writes {name: (array (height, width), 'half' | 'float')} as a ZIP-compressed
    scanline EXR; `attributes` adds string attributes."""
    names = sorted(channels)
    height, width = channels[names[0]][0].shape
    types = {name: (1 if channels[name][1] == "half" else 2) for name in names}
    chlist = (
        b"".join(
            n.encode() + b"\0" + struct.pack("<iB3xii", types[n], 0, 1, 1)
            for n in names
        )
        + b"\0"
    )
    header = struct.pack("<II", 20000630, 2)
    header += _attribute("channels", "chlist", chlist)
    header += _attribute("compression", "compression", bytes([ZIP_COMPRESSION]))
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header += _attribute("dataWindow", "box2i", window)
    header += _attribute("displayWindow", "box2i", window)
    header += _attribute("lineOrder", "lineOrder", bytes([0]))
    header += _attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += _attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    header += _attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))
    for key, value in sorted((attributes or {}).items()):
        header += _attribute(key, "string", value.encode())
    header += b"\0"
    lines = LINES_PER_CHUNK[ZIP_COMPRESSION]
    chunks = []
    for y in range(0, height, lines):
        parts = []
        for row in range(y, min(y + lines, height)):
            for n in names:
                dtype = np.float16 if types[n] == 1 else np.float32
                parts.append(
                    np.ascontiguousarray(channels[n][0][row], dtype=dtype).tobytes()
                )
        raw = b"".join(parts)
        packed = _zip_encode(raw)
        block = packed if len(packed) < len(raw) else raw
        chunks.append(struct.pack("<ii", y, len(block)) + block)
    offset = len(header) + 8 * len(chunks)
    table = b""
    for chunk in chunks:
        table += struct.pack("<Q", offset)
        offset += len(chunk)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(chunks))
