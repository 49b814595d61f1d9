#!/usr/bin/env python3
"""Writes scenes/mitsuba/smoke.vol, the density grid of scenes/mitsuba/cornell-media.xml: five
soft blobs stacked into a plume, with a little ripple, 24^3 samples in Mitsuba's .vol format
(version 3, float32, one channel, x fastest). The output is the same every time."""

import math
import struct
from pathlib import Path

OUT = Path(__file__).resolve().parent.parent / "scenes" / "mitsuba" / "smoke.vol"

N = 24
BLOBS = [
    (
        0.5 + 0.18 * math.cos(a),
        0.35 + 0.12 * k,
        0.5 + 0.18 * math.sin(a),
        0.16 - 0.02 * k,
    )
    for k, a in enumerate([0.0, 1.3, 2.6, 3.9, 5.2])
]


def density(p):
    d = 0.0
    for bx, by, bz, r in BLOBS:
        d += math.exp(
            -((p[0] - bx) ** 2 + (p[1] - by) ** 2 + (p[2] - bz) ** 2) / (r * r)
        )
    d *= 0.75 + 0.25 * math.sin(17 * p[0] + 3) * math.sin(13 * p[1] + 1) * math.sin(
        19 * p[2] + 2
    )
    return min(d, 1.0)


def main():
    data = [
        density(((x + 0.5) / N, (y + 0.5) / N, (z + 0.5) / N))
        for z in range(N)
        for y in range(N)
        for x in range(N)
    ]
    header = b"VOL" + bytes([3]) + struct.pack("<iiiii", 1, N, N, N, 1)
    header += struct.pack("<6f", 0, 0, 0, 1, 1, 1)
    with open(OUT, "wb") as f:
        f.write(header + struct.pack(f"<{len(data)}f", *data))


if __name__ == "__main__":
    main()
