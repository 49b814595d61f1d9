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

import os

from path_frames import alternate, frames_arguments, medians, render_seconds


def scenes(shared):
    course = os.path.join(shared, "scenes", "course", "willemsen")
    return {
        "spheres": os.path.join(course, "scenes_A", "spheres_1K.xml"),
        "room": os.path.join(course, "scenes_A", "CornellRoom_wMirroredSpheres.xml"),
        "dragon": os.path.join(course, "scenes_B", "StanfordDragon_Instanced.json"),
        "bunnies": os.path.join(course, "scenes_B", "rowOfBunnys.json"),
    }


def main():
    def extra(ap):
        ap.add_argument("--rpp", default="1,4,16", help="comma-separated rays a pixel")
        ap.add_argument("--size", type=int, default=1024)

    parse = frames_arguments(__doc__, scenes, 3, "/tmp/glint-course-frames.png")
    a, bins, table = parse(extra)
    size = str(a.size)
    for rpp in a.rpp.split(","):
        for scene in a.scenes:

            def render(b, args=(table[scene], "-r", rpp, "-w", size, "-h", size)):
                return render_seconds(b, list(args), a.threads, a.out)

            times = alternate(bins, a.rounds, render)
            print(f"{scene:8} {rpp:>3} rpp  {medians(bins, times)}", flush=True)


if __name__ == "__main__":
    main()
