"""Load time and peak memory of a glTF model: Glint's reader against Blender's importer.

Both run as fresh processes, alternating, ROUNDS times; the figures are medians.
- Glint: `glint render MODEL --stats` at 16 x 12 pixels, 1 sample; the load stage's time as
  `--stats` prints it, and the process's peak resident memory (its own `--stats` figure).
- Blender: `blender -b --factory-startup` running `bpy.ops.import_scene.gltf` on the model; the
  import's wall time measured around the call inside Blender, and the process's peak resident
  memory (getrusage) less what it held before the import.

Usage: python3 bench/gltf_load.py [MODEL] [--rounds N] [--glint target/release/glint]
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_MODEL = (
    ROOT.parent / "shared/gltf/TextureCoordinateTest/TextureCoordinateTest.gltf"
)

BLENDER_SCRIPT = """
import resource, sys, time
import bpy
import numpy as np
# Debian 12's Blender 3.4 importer uses numpy.bool, which its numpy 1.24 removed.
if not hasattr(np, "bool"):
    np.bool = bool
path = sys.argv[sys.argv.index("--") + 1]
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
bpy.ops.import_scene.gltf(filepath=path)
elapsed = time.perf_counter() - start
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(f"IMPORT {elapsed:.6f} {before} {after}", flush=True)
"""


def glint_round(glint: Path, model: Path) -> tuple[float, float]:
    out = subprocess.run(
        [
            str(glint),
            "render",
            str(model),
            "-o",
            "/tmp/gltf-load-bench.png",
            "-w",
            "16",
            "-h",
            "12",
            "-r",
            "1",
            "--stats",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stderr
    load = float(re.search(r"^\s+load\s+([\d.]+) s", out, re.MULTILINE).group(1))
    peak = re.search(r"peak resident\s+([\d.]+) (KiB|MiB|GiB)", out)
    scale = {"KiB": 1 / 1024, "MiB": 1.0, "GiB": 1024.0}[peak.group(2)]
    return load, float(peak.group(1)) * scale


def blender_environment() -> dict[str, str]:
    """This environment without pyenv's shims on PATH: Debian's Blender finds its Python
    prefix (and Debian's numpy) from the first python3.11 on PATH."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join(
        p for p in env.get("PATH", "").split(os.pathsep) if ".pyenv" not in p
    )
    return env


def blender_round(model: Path, script: Path) -> tuple[float, float, float]:
    out = subprocess.run(
        [
            "blender",
            "-b",
            "--factory-startup",
            "--python",
            str(script),
            "--",
            str(model),
        ],
        capture_output=True,
        text=True,
        check=True,
        env=blender_environment(),
    ).stdout
    _, elapsed, before, after = (
        re.search(r"^IMPORT .*$", out, re.MULTILINE).group(0).split()
    )
    # ru_maxrss is in KiB on Linux.
    return float(elapsed), (int(after) - int(before)) / 1024, int(after) / 1024


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", nargs="?", type=Path, default=DEFAULT_MODEL)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--glint", type=Path, default=ROOT / "target/release/glint")
    args = parser.parse_args()
    script = Path(tempfile.mkdtemp()) / "import_gltf.py"
    script.write_text(BLENDER_SCRIPT)
    glint, blender = [], []
    for _ in range(args.rounds):
        glint.append(glint_round(args.glint, args.model))
        blender.append(blender_round(args.model, script))
    g_load = statistics.median(r[0] for r in glint)
    g_peak = statistics.median(r[1] for r in glint)
    b_load = statistics.median(r[0] for r in blender)
    b_growth = statistics.median(r[1] for r in blender)
    b_peak = statistics.median(r[2] for r in blender)
    size = args.model.stat().st_size
    print(
        f"model: {args.model.name} ({size} bytes), {args.rounds} alternating rounds, medians"
    )
    print("| reader | load (ms) | peak resident (MiB) |")
    print("| --- | ---: | ---: |")
    print(
        f"| Glint (`glint render --stats`, load stage) | {g_load * 1e3:.1f} | {g_peak:.1f} "
        "(whole process) |"
    )
    print(
        f"| Blender 3.4 `import_scene.gltf` | {b_load * 1e3:.1f} | {b_peak:.1f} (whole "
        f"process; the import grew it by {b_growth:.1f}) |"
    )
    print(f"Glint loads it {b_load / g_load:.1f}x faster")
    return 0


if __name__ == "__main__":
    sys.exit(main())
