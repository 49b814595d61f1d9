#!/usr/bin/env python3
"""Whole-frame thread scaling (issue 14): how much faster `glint render` finishes a frame on N
threads than on one.

Four workloads, each a whole process (scene load, BVH build, render, image write):
  spheres_1K                    course integrator, 1024x1024, 9 rays per pixel
  CornellRoom_wMirroredSpheres  course integrator, 1024x1024, 16 rays per pixel
  StanfordDragon_Instanced      course integrator, 1024x1024, 16 rays per pixel (loads dragon.obj)
  path Cornell                  path tracer on ../shared/refs/cornell/cornell.json, 256x256, 64 spp
Each writes a PNG. Each round runs every workload at every thread count (`-n N`), the thread
counts in increasing order on even rounds and decreasing order on odd ones, so that a slow spell
of a shared machine falls on both ends. Reported per workload and thread count: the median over
the rounds of the process's wall time and of the render stage alone (the image's
`glint.render_time`; `--stats` is not used, its counting pass would add to the frame), and the
scaling T(1) / T(N) of both. The render stage's scaling is what the renderer's parallel loop
achieves; the whole frame's includes the load, build and write.

  bench/scaling.py [--glint PATH[,PATH...]] [--shared DIR] [--threads 1,4,8,16] [--rounds 3]
                   [--size F] [--only NAME[,NAME...]] [--ceiling | --copies] [--json OUT]

--size scales every image's side (0.25: a quarter the width and height), for a quick run.
Several glints (comma-separated) run side by side, alternating within each round.
--ceiling measures the machine instead: N copies of the single-thread render at once, for each
N of --threads; N * T(1 copy) / T(N copies) is what N threads could reach at best on it (shared
caches, memory bandwidth, and clocks that drop as more cores run).
--copies measures both in the same rounds: after each N-thread frame of the first glint, N
single-thread copies of it at once; its column "copies x" is T(1 thread) * sum of the copies'
speeds (1 / each copy's render time, median over the rounds), the throughput of the machine's N
cores on N independent frames as a speedup, the figure an N-thread render with work stealing
could reach; "spread" is the slowest copy's render time over the fastest's.
Needs only Python 3 and a built glint (default target/release/glint).
"""

import argparse
import json
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def workloads(shared, size):
    course = os.path.join(shared, "scenes", "course", "willemsen")

    def px(n):
        return str(max(8, round(n * size)))

    return [
        (
            "spheres_1K",
            os.path.join(course, "scenes_A", "spheres_1K.xml"),
            ["-w", px(1024), "-h", px(1024), "-r", "9"],
        ),
        (
            "CornellRoom_wMirroredSpheres",
            os.path.join(course, "scenes_A", "CornellRoom_wMirroredSpheres.xml"),
            ["-w", px(1024), "-h", px(1024), "-r", "16"],
        ),
        (
            "StanfordDragon_Instanced",
            os.path.join(course, "scenes_B", "StanfordDragon_Instanced.json"),
            ["-w", px(1024), "-h", px(1024), "-r", "16"],
        ),
        (
            "path_Cornell",
            os.path.join(shared, "refs", "cornell", "cornell.json"),
            [
                "--integrator",
                "path",
                "--spp",
                "64",
                "-w",
                px(256),
                "-h",
                px(256),
                "--seed",
                "1",
            ],
        ),
    ]


def png_text(path):
    """The tEXt chunks of a PNG, as a dict."""
    with open(path, "rb") as f:
        data = f.read()
    text, at = {}, 8
    while at + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[at : at + 8])
        if kind == b"tEXt":
            key, _, value = data[at + 8 : at + 8 + length].partition(b"\0")
            text[key.decode("latin-1")] = value.decode("latin-1")
        at += 12 + length
    return text


def run_once(glint, scene, args, threads, out_dir):
    out = os.path.join(out_dir, "frame.png")
    cmd = [glint, "render", scene, *args, "-n", str(threads), "-o", out]
    start = time.perf_counter()
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")
    render = png_text(out).get("glint.render_time")
    if render is None:
        sys.exit(f"no glint.render_time in the image of {' '.join(cmd)}")
    os.remove(out)
    return wall, float(render)


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def run_copies(glint, scene, args, copies, out_dir):
    """`copies` single-thread renders of the same frame at once; their render times."""
    procs = []
    for c in range(copies):
        out = os.path.join(out_dir, f"copy{c}.png")
        cmd = [glint, "render", scene, *args, "-n", "1", "-o", out]
        procs.append(
            (
                cmd,
                out,
                subprocess.Popen(
                    cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
                ),
            )
        )
    renders = []
    for cmd, out, proc in procs:
        _, err = proc.communicate()
        if proc.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{err}")
        renders.append(float(png_text(out)["glint.render_time"]))
        os.remove(out)
    return renders


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--glint",
        default=os.path.join(ROOT, "target", "release", "glint"),
        help="one glint, or several separated by commas, run side by side",
    )
    ap.add_argument("--shared", default=os.path.join(ROOT, "..", "shared"))
    ap.add_argument("--threads", default="1,4,8,16")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--size", type=float, default=1.0)
    ap.add_argument(
        "--only", default="", help="workloads whose names contain one of these (commas)"
    )
    ap.add_argument(
        "--ceiling",
        action="store_true",
        help="instead: N single-thread copies at once for each N of --threads",
    )
    ap.add_argument(
        "--copies",
        action="store_true",
        help="also N single-thread copies at once after each N-thread frame (the ceiling, "
        "measured in the same rounds)",
    )
    ap.add_argument("--json", default="")
    a = ap.parse_args()
    counts = [int(t) for t in a.threads.split(",")]
    if 1 not in counts:
        sys.exit("--threads must include 1 (scaling is against one thread)")
    glints = a.glint.split(",")
    only = a.only.split(",")
    loads = [w for w in workloads(a.shared, a.size) if any(o in w[0] for o in only)]
    cpus = (
        len(os.sched_getaffinity(0))
        if hasattr(os, "sched_getaffinity")
        else os.cpu_count()
    )
    print(
        f"{cpu_model()}; {cpus} CPUs usable; threads {counts}; {a.rounds} rounds; "
        f"size {a.size}",
        flush=True,
    )
    if a.copies and a.ceiling:
        sys.exit("--copies and --ceiling exclude each other")
    times = {(g, w[0], n): ([], []) for g in glints for w in loads for n in counts}
    # Per workload and N: each round's sum of the copies' speeds and slowest / fastest copy.
    copies = {(w[0], n): ([], []) for w in loads for n in counts}
    with tempfile.TemporaryDirectory(prefix="glint-scaling-") as tmp:
        for r in range(max(1, a.rounds)):
            order = counts if r % 2 == 0 else counts[::-1]
            for name, scene, args in loads:
                for n in order:
                    for g in glints if r % 2 == 0 else glints[::-1]:
                        if a.ceiling:
                            renders = run_copies(g, scene, args, n, tmp)
                            wall, render = max(renders), statistics.median(renders)
                        else:
                            wall, render = run_once(g, scene, args, n, tmp)
                        times[(g, name, n)][0].append(wall)
                        times[(g, name, n)][1].append(render)
                        print(
                            f"round {r} {g} {name} {n:2d}: wall {wall:7.3f} s, "
                            f"render {render:7.3f} s",
                            file=sys.stderr,
                            flush=True,
                        )
                        if a.copies and n > 1 and g == glints[0]:
                            renders = run_copies(g, scene, args, n, tmp)
                            copies[(name, n)][0].append(sum(1 / t for t in renders))
                            copies[(name, n)][1].append(max(renders) / min(renders))
                            print(
                                f"round {r} {g} {name} {n:2d} copies: render "
                                f"{min(renders):7.3f} .. {max(renders):7.3f} s",
                                file=sys.stderr,
                                flush=True,
                            )
    med = statistics.median
    rows = []
    if a.ceiling:
        print(
            'N copies of a 1-thread render at once: "wall" the slowest copy\'s render, '
            '"render" the median copy\'s; x: N * T(1 copy) / T(N copies), what N threads '
            "could reach on this machine"
        )
    else:
        print('"wall": the whole process; "render": the render stage; x: T(1) / T(N)')
    for g in glints:
        print(g)
        beside = a.copies and g == glints[0]
        print(
            f"{'workload':30} {'threads':>7} {'wall s':>8} {'render s':>8} {'frame x':>8} "
            f"{'render x':>8}" + (f" {'copies x':>8} {'spread':>6}" if beside else "")
        )
        for name, *_ in loads:
            w1, r1 = med(times[(g, name, 1)][0]), med(times[(g, name, 1)][1])
            for n in counts:
                w, rt = med(times[(g, name, n)][0]), med(times[(g, name, n)][1])
                k = n if a.ceiling else 1
                row = {
                    "glint": g,
                    "workload": name,
                    "threads": n,
                    "wall_s": w,
                    "render_s": rt,
                    "frame_scaling": k * w1 / w,
                    "render_scaling": k * r1 / rt,
                }
                line = (
                    f"{name:30} {n:7d} {w:8.3f} {rt:8.3f} {k * w1 / w:8.2f} "
                    f"{k * r1 / rt:8.2f}"
                )
                speeds, spreads = copies[(name, n)]
                if beside and speeds:
                    row["copies_scaling"] = r1 * med(speeds)
                    row["copies_spread"] = med(spreads)
                    line += f" {r1 * med(speeds):8.2f} {med(spreads):6.2f}"
                rows.append(row)
                print(line)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(
                {
                    "cpu": cpu_model(),
                    "cpus": cpus,
                    "rounds": a.rounds,
                    "size": a.size,
                    "ceiling": a.ceiling,
                    "copies": a.copies,
                    "rows": rows,
                },
                f,
                indent=1,
            )


if __name__ == "__main__":
    main()
