#!/usr/bin/env python3
"""The --stats table of the BVH split methods (-s) on course scenes and a 1M-triangle mesh:
build time, nodes, leaves, depth, SAH cost, nodes and triangle blocks per camera ray, render
time. Build and render times are medians of --rounds runs, the methods alternating.

Usage: bench/split_methods.py [--glint target/release/glint] [--rounds 3] [--size 512] [--rpp 16]
Needs ../shared (the course corpus and ../shared/models/igea-sub4.ply, which it turns into an
OBJ scene in a temporary folder: the scene loader reads OBJ meshes)."""

import argparse
import os
import re
import statistics
import struct
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "shared"))
COURSE = os.path.join(SHARED, "scenes", "course", "willemsen")
METHODS = ["objectMedian", "spatialMedian", "sah"]

IGEA_SCENE = """{"scene": {
  "camera": [{"position": "0 0 0.25", "viewDir": "0 0 -1", "focalLength": 1.0,
              "imagePlaneWidth": 0.5, "_name": "main", "_type": "perspective"}],
  "light": [{"position": "0.2 0.3 0.4", "intensity": "1 1 1", "_type": "point"}],
  "shader": [{"diffuse": "0.8 0.7 0.6", "_name": "clay", "_type": "Lambertian"}],
  "shape": [{"file": "igea-sub4.obj", "shader": {"_ref": "clay"}, "_name": "igea",
             "_type": "mesh"}],
  "bgColor": "0.2 0.2 0.2"}}
"""


def igea_scene(folder):
    """igea-sub4.ply (binary, triangles) as an OBJ and a course scene framing it."""
    with open(os.path.join(SHARED, "models", "igea-sub4.ply"), "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    vertices = int(re.search(r"element vertex (\d+)", header).group(1))
    faces = int(re.search(r"element face (\d+)", header).group(1))
    with open(os.path.join(folder, "igea-sub4.obj"), "w") as obj:
        obj.writelines(
            f"v {x:.7g} {y:.7g} {z:.7g}\n"
            for x, y, z in struct.iter_unpack("<3f", data[end : end + 12 * vertices])
        )
        start = end + 12 * vertices
        triangles = struct.iter_unpack("<B3i", data[start : start + 13 * faces])
        obj.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for _, a, b, c in triangles)
    path = os.path.join(folder, "igea.json")
    with open(path, "w") as f:
        f.write(IGEA_SCENE)
    return path


def run(glint, scene, method, args, image):
    out = subprocess.run(
        [
            glint,
            "-i",
            scene,
            "-o",
            image,
            "-w",
            str(args.size),
            "-h",
            str(args.size),
            "-r",
            str(args.rpp),
            "-s",
            method,
            "--stats",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stderr
    tree = re.search(
        r"built in ([\d.]+) ms; \d+ trees?, (\d+) nodes, (\d+) leaves, "
        r"depth (\d+), SAH cost ([\d.]+)",
        out,
    )
    walk = re.search(r"([\d.]+) nodes and ([\d.]+) triangle blocks per camera ray", out)
    render = re.search(r"rpp in ([\d.]+) s", out)
    return (
        float(tree.group(1)),
        int(tree.group(2)),
        int(tree.group(3)),
        int(tree.group(4)),
        float(tree.group(5)),
        float(walk.group(1)),
        float(walk.group(2)),
        float(render.group(1)),
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument(
        "--glint", default=os.path.join(HERE, "..", "target", "release", "glint")
    )
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rpp", type=int, default=16)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        scenes = {
            "spheres_1K": os.path.join(COURSE, "scenes_A", "spheres_1K.xml"),
            "StanfordDragon_Instanced": os.path.join(
                COURSE, "scenes_B", "StanfordDragon_Instanced.json"
            ),
            "igea-sub4 (1.07M tris)": igea_scene(folder),
        }
        image = os.path.join(folder, "out.png")
        runs = {}
        for _ in range(args.rounds):
            for name, scene in scenes.items():
                for method in METHODS:
                    runs.setdefault((name, method), []).append(
                        run(args.glint, scene, method, args, image)
                    )
    print(
        f"{args.size}x{args.size}, {args.rpp} rpp, course integrator; build and render "
        f"times: medians of {args.rounds} rounds"
    )
    print(
        f"{'scene':26} {'method':14} {'build ms':>9} {'nodes':>7} {'leaves':>7} "
        f"{'depth':>5} {'SAH cost':>8} {'nodes/ray':>9} {'blocks/ray':>10} {'render s':>8}"
    )
    for (name, method), values in runs.items():
        first = values[0]
        build = statistics.median(v[0] for v in values)
        render = statistics.median(v[7] for v in values)
        print(
            f"{name:26} {method:14} {build:9.1f} {first[1]:7d} {first[2]:7d} {first[3]:5d} "
            f"{first[4]:8.2f} {first[5]:9.2f} {first[6]:10.2f} {render:8.2f}"
        )


if __name__ == "__main__":
    main()
