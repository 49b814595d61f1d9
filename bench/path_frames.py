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


def alternate(bins, rounds, render):
    """`render(b)` for every binary b, `rounds` times, the order reversed every other round:
    the times of each binary."""
    times = {b: [] for b in bins}
    for r in range(rounds):
        for b in bins if r % 2 == 0 else bins[::-1]:
            times[b].append(render(b))
    return times


def medians(bins, times):
    """Each binary's median time and its ratio to the first binary's, as one line's cells."""
    first = statistics.median(times[bins[0]])
    return "  ".join(
        f"{b}: {statistics.median(times[b]):.3f} s "
        f"({statistics.median(times[b]) / first if first > 0 else float('nan'):.3f})"
        for b in bins
    )


def frames_arguments(doc, table, rounds, out):
    """The options these frame benchmarks share (--glint, --rounds, --threads, --shared, --out
    and the scenes, names of `table(shared)`), with `extra(parser)` adding a script's own:
    the parsed options, the binaries and the scene table."""

    def parse(extra=lambda ap: None):
        ap = argparse.ArgumentParser(description=doc.splitlines()[0])
        ap.add_argument("--glint", required=True, help="comma-separated glint binaries")
        ap.add_argument("--rounds", type=int, default=rounds)
        ap.add_argument("--threads", type=int, default=1)
        ap.add_argument("--shared", default=SHARED)
        ap.add_argument("--out", default=out)
        extra(ap)
        names = list(table(SHARED))
        ap.add_argument("scenes", nargs="*", default=names)
        a = ap.parse_args()
        scenes_of = table(a.shared)
        unknown = [s for s in a.scenes if s not in scenes_of]
        if unknown:
            sys.exit(f"unknown scene(s) {unknown}; known: {sorted(scenes_of)}")
        return a, a.glint.split(","), scenes_of

    return parse


def main():
    parse = frames_arguments(__doc__, scenes, 5, "/tmp/glint-path-frames.exr")
    a, bins, table = parse()
    for scene in a.scenes:

        def render(b, args=table[scene]):
            return render_seconds(b, args, a.threads, a.out)

        times = alternate(bins, a.rounds, render)
        rounds = [round(x / y, 3) for x, y in zip(times[bins[-1]], times[bins[0]])]
        print(f"{scene:8} {medians(bins, times)}  last/first by round {rounds}")


if __name__ == "__main__":
    main()
