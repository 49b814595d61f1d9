#!/usr/bin/env python3
"""Single rays of one ray set, split into the rays that hit and the rays that miss, traced by
Glint and native Embree side by side: where an incoherent set is slower than `rtcIntersect1`,
this says which of its rays are.

  python3 bench/hit_split.py [--glint A,B,...] [--mesh dragon] [--set random] [--rounds 3]
                             [--no-embree]

Needs the ray files and mesh of `bench/embree_compare.sh` (target/bench-rays/NAME.SET.rays,
NAME.bin) and its `embree_native`; run that script once first. The split follows the first
glint's own answers (`--write-t`); the parts are written to target/bench-rays/split/. Each
round runs every glint (in alternating order) and then Embree on each part; printed are the
medians of the rounds (each run the best of 3 passes) and each glint's ratio to Embree's
single rays and to the first glint. It found that the dragon's random rays lost to Embree on the
rays that hit: bench/results/2026-11-27-issue14-pass21-zen4-sorting-network.md.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys

import numpy as np

MESHES = {
    "stanford-bunny": "{shared}/models/stanford-bunny.obj",
    "igea-sub4": "{shared}/models/igea-sub4.ply",
    "dragon": "{shared}/scenes/course/willemsen/scenes_B/objFiles/dragon.obj",
}


def last_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--glint", default="target/release/glint")
    ap.add_argument("--embree", default="target/embree_native")
    ap.add_argument("--rays", default="target/bench-rays")
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--mesh", default="dragon", choices=sorted(MESHES))
    ap.add_argument("--set", default="random")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--no-embree", action="store_true")
    a = ap.parse_args()
    glints = a.glint.split(",")
    mesh = MESHES[a.mesh].format(shared=a.shared)
    rayfile = os.path.join(a.rays, f"{a.mesh}.{a.set}.rays")
    if not os.path.exists(rayfile):
        sys.exit(f"{rayfile} is missing: run bench/embree_compare.sh first")
    split = os.path.join(a.rays, "split")
    os.makedirs(split, exist_ok=True)
    tfile = os.path.join(split, f"{a.mesh}.{a.set}.t")
    subprocess.run(
        [
            glints[0],
            "bench",
            "rays",
            "--mesh",
            mesh,
            "--rays",
            rayfile,
            "--repeat",
            "1",
            "--write-t",
            tfile,
        ],
        check=True,
        capture_output=True,
    )
    t = np.fromfile(tfile, dtype=np.float32)
    rays = np.fromfile(rayfile, dtype=np.float32).reshape(-1, 6)
    if len(t) != len(rays):
        sys.exit(f"{tfile}: {len(t)} distances for {len(rays)} rays")
    miss = np.isinf(t)
    parts = {}
    for name, select in (("hit", ~miss), ("miss", miss)):
        path = os.path.join(split, f"{a.mesh}.{a.set}.{name}.rays")
        rays[select].tofile(path)
        parts[name] = (path, int(select.sum()))
    runs = {(p, g): [] for p in parts for g in glints + ["embree"]}
    for r in range(a.rounds):
        for part, (path, _) in parts.items():
            for g in glints if r % 2 == 0 else glints[::-1]:
                j = last_json(
                    [
                        g,
                        "bench",
                        "rays",
                        "--mesh",
                        mesh,
                        "--rays",
                        path,
                        "--threads",
                        "1",
                        "--repeat",
                        "3",
                    ]
                )
                runs[(part, g)].append(j["mrays_per_s"])
            if not a.no_embree:
                j = last_json(
                    [a.embree, os.path.join(a.rays, f"{a.mesh}.bin"), path, "3"]
                )
                runs[(part, "embree")].append(j["single_mrays"])
    print(
        f"{a.mesh} {a.set}: single rays, Mrays/s, medians of {a.rounds} alternating rounds"
    )
    for part, (_, count) in parts.items():
        e = statistics.median(runs[(part, "embree")]) if not a.no_embree else None
        first = statistics.median(runs[(part, glints[0])])
        cells = []
        for g in glints:
            m = statistics.median(runs[(part, g)])
            ratio = f" /E1 {m / e:.3f}" if e else ""
            cells.append(f"{g}: {m:7.3f}{ratio} /A {m / first:.3f}")
        embree = f"  embree {e:7.3f}" if e else ""
        print(f"  {part:4} {count:8d} rays  " + "  ".join(cells) + embree)


if __name__ == "__main__":
    main()
