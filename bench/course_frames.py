#!/usr/bin/env python3
"""Course-integrator frames of several glint binaries side by side, alternating.

    python3 bench/course_frames.py --glint A,B[,C...] [--rpp 1,4,16] [--rounds 3]
        [--size 1024] [--threads 1] [SCENE ...]

For each number of rays a pixel, each round renders every scene with every binary (the order
reversed every other round), one process a frame, and reads the render time glint prints
("in X s"); prints per scene and rays a pixel the median of each binary and its ratio to the
first's. Scenes (the issue's whole-frame workloads and one more mesh scene): spheres
(spheres_1K.xml), room (CornellRoom_wMirroredSpheres.xml), dragon
(StanfordDragon_Instanced.json), bunnies (rowOfBunnys.json); square frames --size wide.
"""

import argparse
import os
import statistics
import sys

from path_frames import SHARED, render_seconds


def scenes(shared):
    course = os.path.join(shared, "scenes", "course", "willemsen")
    return {
        "spheres": os.path.join(course, "scenes_A", "spheres_1K.xml"),
        "room": os.path.join(course, "scenes_A", "CornellRoom_wMirroredSpheres.xml"),
        "dragon": os.path.join(course, "scenes_B", "StanfordDragon_Instanced.json"),
        "bunnies": os.path.join(course, "scenes_B", "rowOfBunnys.json"),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--glint", required=True, help="comma-separated glint binaries")
    ap.add_argument("--rpp", default="1,4,16", help="comma-separated rays a pixel")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--shared", default=SHARED)
    ap.add_argument("--out", default="/tmp/glint-course-frames.png")
    ap.add_argument(
        "scenes", nargs="*", default=["spheres", "room", "dragon", "bunnies"]
    )
    a = ap.parse_args()
    bins = a.glint.split(",")
    table = scenes(a.shared)
    unknown = [s for s in a.scenes if s not in table]
    if unknown:
        sys.exit(f"unknown scene(s) {unknown}; known: {sorted(table)}")
    size = str(a.size)
    for rpp in a.rpp.split(","):
        for scene in a.scenes:
            args = [table[scene], "-r", rpp, "-w", size, "-h", size]
            times = {b: [] for b in bins}
            for r in range(a.rounds):
                for b in bins if r % 2 == 0 else bins[::-1]:
                    times[b].append(render_seconds(b, args, a.threads, a.out))
            first = statistics.median(times[bins[0]])
            cells = "  ".join(
                f"{b}: {statistics.median(times[b]):.3f} s "
                f"({statistics.median(times[b]) / first:.3f})"
                for b in bins
            )
            print(f"{scene:8} {rpp:>3} rpp  {cells}", flush=True)


if __name__ == "__main__":
    main()
