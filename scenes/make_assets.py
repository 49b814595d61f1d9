"""Write the example scenes' images: a checkerboard and a small sky as a cube map.

Run from anywhere with the standard library alone (`python3 scenes/make_assets.py`); it
rewrites scenes/images/checker.png, sky_cross.png and the six sky_<face>.png files, byte for
byte the same on every run, so that the scenes own every file they read.
"""

import math
import struct
import zlib
from pathlib import Path

IMAGES = Path(__file__).resolve().parent / "images"
FACE = 128  # side of a cube-map face in pixels: enough that the gradient shows no steps


def write_png(path, width, height, pixel):
    """An 8-bit RGB PNG whose pixel (x, y), row 0 at the top, is pixel(x, y) in [0, 1]^3."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # filter type None
        for x in range(width):
            rows.extend(round(255 * min(max(c, 0.0), 1.0)) for c in pixel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(bytes(rows), 9))
        + chunk(b"IEND", b"")
    )


def checker(x, y):
    """8 x 8 squares of 8 pixels, cream and brick red."""
    return (0.95, 0.9, 0.8) if (x // 8 + y // 8) % 2 == 0 else (0.7, 0.15, 0.1)


SUN = (0.48, 0.6, 0.64)


def sky(d):
    """Radiance seen along direction d: a blue gradient above, a warm sun, brown ground."""
    length = math.sqrt(sum(c * c for c in d))
    x, y, z = (c / length for c in d)
    if y < 0:
        return (0.3, 0.26, 0.22)
    sun_length = math.sqrt(sum(c * c for c in SUN))
    if (x * SUN[0] + y * SUN[1] + z * SUN[2]) / sun_length > 0.97:
        return (1.0, 0.95, 0.8)
    k = math.sqrt(y)
    horizon, zenith = (0.85, 0.9, 0.95), (0.25, 0.45, 0.85)
    return tuple(h + (t - h) * k for h, t in zip(horizon, zenith))


# The direction of texel (s, t) in [-1, 1]^2 of each face, t growing down the image: the
# inverse of the OpenGL cube-map table that Glint's CubeMap::face_coordinates follows.
FACES = {
    "posX": lambda s, t: (1, -t, -s),
    "negX": lambda s, t: (-1, -t, s),
    "posY": lambda s, t: (s, 1, t),
    "negY": lambda s, t: (s, -1, -t),
    "posZ": lambda s, t: (s, -t, 1),
    "negZ": lambda s, t: (-s, -t, -1),
}


def face_pixel(name, x, y):
    s = 2 * (x + 0.5) / FACE - 1
    t = 2 * (y + 0.5) / FACE - 1
    return sky(FACES[name](s, t))


# The vertical cross, 3 x 4 faces: +Y above -X +Z +X, then -Y, then -Z turned by 180 degrees.
CROSS = {(1, 0): "posY", (0, 1): "negX", (1, 1): "posZ", (2, 1): "posX", (1, 2): "negY"}


def cross_pixel(x, y):
    cell = (x // FACE, y // FACE)
    fx, fy = x % FACE, y % FACE
    if cell == (1, 3):
        return face_pixel("negZ", FACE - 1 - fx, FACE - 1 - fy)
    if cell in CROSS:
        return face_pixel(CROSS[cell], fx, fy)
    return (0.0, 0.0, 0.0)


def main():
    IMAGES.mkdir(exist_ok=True)
    write_png(IMAGES / "checker.png", 64, 64, checker)
    for name in FACES:
        write_png(
            IMAGES / f"sky_{name}.png",
            FACE,
            FACE,
            lambda x, y, name=name: face_pixel(name, x, y),
        )
    write_png(IMAGES / "sky_cross.png", 3 * FACE, 4 * FACE, cross_pixel)


if __name__ == "__main__":
    main()
