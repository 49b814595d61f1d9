#!/usr/bin/env python3
"""Glint against Mitsuba 3 on Mitsuba's own test scenes, side by side in one run.

Each scene of ../shared/mitsuba/tests/scenes (`--filter participating_media`: the volume
scenes) is rendered at the sample count of Mitsuba's rule (2,000,000 / pixels) by Glint's CLI
and by Mitsuba 3 in the variants `scalar_rgb` and `llvm_ad_rgb`, in alternating rounds; the
script prints each one's median time (scene load and render, as each front end does it) and
the ratios Mitsuba / Glint (above 1: Glint is faster).

    python3 bench/mitsuba_suite.py --glint target/release/glint [--rounds 3] [--filter text]

Mitsuba comes from pip (`../shared/bench/setup-peers.sh`); each Mitsuba variant runs in its own
process, which times only `load_file` and `render` (not Python's start or the JIT variant's
first compilation of its kernels: one warm-up render per scene is discarded, as is Glint's).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SUITE = ROOT.parent / "shared" / "mitsuba" / "tests" / "scenes"
BUDGET = 2_000_000

MITSUBA_WORKER = r"""
import json, sys, time
import mitsuba as mi
mi.set_variant(sys.argv[1])
scene_path, spp, repeats = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
times = []
for i in range(repeats + 1):
    start = time.perf_counter()
    scene = mi.load_file(scene_path)
    image = mi.render(scene, spp=spp)
    mi.Bitmap(image)  # forces the evaluation of a JIT variant's image
    elapsed = time.perf_counter() - start
    if i > 0:
        times.append(elapsed)
print(json.dumps(times))
"""


def scenes(filter_text):
    for folder in sorted(SUITE.iterdir()):
        if not folder.is_dir():
            continue
        for scene in sorted(folder.glob("*.xml")):
            if filter_text is None or filter_text in str(scene):
                yield scene


def film_size(scene):
    """The reference's size, which is the film's."""
    name = scene.stem.rsplit("_", 1)[0]
    ref = scene.parent / "refs" / f"{name}_ref_rgb.exr"
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    bitmap = mi.Bitmap(str(ref))
    return bitmap.width(), bitmap.height()


def time_glint(glint, scene, spp, out):
    start = time.perf_counter()
    subprocess.run(
        [str(glint), "render", str(scene), "-o", str(out), "--spp", str(spp)],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    return time.perf_counter() - start


def llvm_environment():
    """Dr.Jit's LLVM back end needs LLVM 19 (14-16 abort): Debian's libllvm19, found by ldconfig
    unless DRJIT_LIBLLVM_PATH names one (as ../shared/bench/setup-peers.sh sets it)."""
    env = dict(os.environ)
    if "DRJIT_LIBLLVM_PATH" not in env:
        listing = subprocess.run(
            ["ldconfig", "-p"], check=False, capture_output=True, text=True
        ).stdout
        for line in listing.splitlines():
            if "libLLVM.so.19" in line and "=>" in line:
                env["DRJIT_LIBLLVM_PATH"] = line.split("=>")[1].strip()
                break
    return env


def time_mitsuba(variant, scene, spp):
    """Seconds, or None when the Mitsuba process fails (its stderr is printed)."""
    try:
        return run_mitsuba(variant, scene, spp)
    except (subprocess.CalledProcessError, ValueError, IndexError) as error:
        stderr = getattr(error, "stderr", "") or ""
        print(
            f"  {variant} failed on {scene.name}: {error} {stderr[-300:]}", flush=True
        )
        return None


def run_mitsuba(variant, scene, spp):
    result = subprocess.run(
        [sys.executable, "-c", MITSUBA_WORKER, variant, str(scene), str(spp), "1"],
        check=True,
        capture_output=True,
        text=True,
        env=llvm_environment(),
    )
    return json.loads(result.stdout.strip().splitlines()[-1])[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--glint", default=str(ROOT / "target" / "release" / "glint"))
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--filter", default=None)
    args = parser.parse_args()
    variants = ["scalar_rgb", "llvm_ad_rgb"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "glint.exr"
        for scene in scenes(args.filter):
            width, height = film_size(scene)
            spp = max(1, BUDGET // (width * height))
            time_glint(args.glint, scene, spp, out)  # warm-up: file cache
            times = {"glint": []} | {v: [] for v in variants}
            for _ in range(args.rounds):
                times["glint"].append(time_glint(args.glint, scene, spp, out))
                for variant in variants:
                    times[variant].append(time_mitsuba(variant, scene, spp))
            medians = {
                k: statistics.median(v) if None not in v else None
                for k, v in times.items()
            }
            name = f"{scene.parent.name}/{scene.stem}"
            rows.append((name, spp, medians))
            peers = [
                f"{v} {medians[v]:.2f} s ({medians[v] / medians['glint']:.2f}x)"
                if medians[v] is not None
                else f"{v} failed"
                for v in variants
            ]
            print(
                f"{name}: {spp} spp, glint {medians['glint']:.2f} s, "
                + ", ".join(peers),
                flush=True,
            )
    for variant in variants:
        ratios = [m[variant] / m["glint"] for _, _, m in rows if m[variant] is not None]
        if ratios:
            print(
                f"{variant} / glint: median {statistics.median(ratios):.2f}x, "
                f"geometric mean {statistics.geometric_mean(ratios):.2f}x over {len(ratios)} scenes"
            )


if __name__ == "__main__":
    main()
