#!/usr/bin/env python3
"""Path-traced frames of several glint binaries side by side, alternating.

    python3 bench/path_frames.py --glint A,B[,C...] [--rounds 5] [--threads 1] [SCENE ...]

Each round renders every scene with every binary (the order reversed every other round), one
process a frame, and reads the render time glint prints ("in X s"); prints per scene the
median of each binary, its ratio to the first's, and the per-round ratios of the last binary
to the first. Scenes: cornell (../shared/refs/cornell, 256x256, 40 spp, the Mitsuba
comparison's), dragon (StanfordDragon_Instanced, 384x384, 16 spp), room
(CornellRoom_wMirroredSpheres, 256x256, 32 spp), bunnies (rowOfBunnys, 384x288, 16 spp).
"""

import argparse
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared"))


def scenes(shared):
    course = os.path.join(shared, "scenes", "course", "willemsen")
    path = ["--integrator", "path"]
    return {
        "cornell": [os.path.join(shared, "refs", "cornell", "cornell.json")]
        + path
        + ["--spp", "40", "--seed", "1", "-w", "256", "-h", "256"],
        "dragon": [os.path.join(course, "scenes_B", "StanfordDragon_Instanced.json")]
        + path
        + ["--spp", "16", "-w", "384", "-h", "384"],
        "room": [os.path.join(course, "scenes_A", "CornellRoom_wMirroredSpheres.xml")]
        + path
        + ["--spp", "32", "-w", "256", "-h", "256"],
        "bunnies": [os.path.join(course, "scenes_B", "rowOfBunnys.json")]
        + path
        + ["--spp", "16", "-w", "384", "-h", "288"],
    }


def render_seconds(glint, args, threads, out):
    result = subprocess.run(
        [glint, "render", *args, "-n", str(threads), "-o", out],
        capture_output=True,
        text=True,
        check=True,
    )
    return float(re.search(r" in ([0-9.]+) s", result.stderr).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--glint", required=True, help="comma-separated glint binaries")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--shared", default=SHARED)
    ap.add_argument("--out", default="/tmp/glint-path-frames.exr")
    ap.add_argument(
        "scenes", nargs="*", default=["cornell", "dragon", "room", "bunnies"]
    )
    a = ap.parse_args()
    bins = a.glint.split(",")
    table = scenes(a.shared)
    unknown = [s for s in a.scenes if s not in table]
    if unknown:
        sys.exit(f"unknown scene(s) {unknown}; known: {sorted(table)}")
    for scene in a.scenes:
        times = {b: [] for b in bins}
        for r in range(a.rounds):
            for b in bins if r % 2 == 0 else bins[::-1]:
                times[b].append(render_seconds(b, table[scene], a.threads, a.out))
        first = statistics.median(times[bins[0]])
        cells = "  ".join(
            f"{b}: {statistics.median(times[b]):.3f} s ({statistics.median(times[b]) / first:.3f})"
            for b in bins
        )
        rounds = [round(x / y, 3) for x, y in zip(times[bins[-1]], times[bins[0]])]
        print(f"{scene:8} {cells}  last/first by round {rounds}")


if __name__ == "__main__":
    main()
