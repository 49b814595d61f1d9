#!/usr/bin/env python3
"""Equal quality, who is faster: Glint's path tracer against Mitsuba 3 on the Cornell box.

For the Cornell box of ../shared/refs/cornell at 256x256, in one run on this machine:
  1. Mitsuba 3 (llvm_ad_rgb, path tracer, unbounded length) renders 64 spp through
     ../shared/bench/make_cornell_ref.py, which times mi.render(mi.load_dict(scene)); best of
     --repeats + 1 runs (the first also compiles Dr.Jit's kernels, later ones find them cached).
  2. Its error E_M = relMSE(mitsuba_64, reference_4096), with
     relMSE(a, r) = mean over pixels and channels of (a - r)^2 / (r^2 + 0.01)
     (the same measure as crates/io/tests/path_cornell.rs).
  3. Glint finds the sample count N at which its own error reaches E_M: one probe render at 64 spp
     gives its per-sample variance, errors are modelled as a/N + c with c the reference's own
     noise (estimated from Mitsuba's figures), N is predicted, then raised by 5% until the error
     measured against the reference is at or below E_M.
  4. Glint renders N spp --repeats times, alternating with Mitsuba's runs; the best wall time of
     the whole process (scene load, BVH build, render, EXR write) is compared with Mitsuba's best
     time of load_dict + render (the headline ratio; Mitsuba's script prints it to 0.1 s, so
     it runs under a wrapper that reads the same two time.time() calls in full) and, as a
     second ratio, with the best wall time of Mitsuba's whole
     process (Python start and import included, so that one favours Glint).
Prints both times and their ratio (below 1: Glint reaches Mitsuba's quality in less time), and
the median of the rounds' own ratios (each Glint run against the Mitsuba run just before it),
which a change in the machine's load between rounds moves less than two best times taken from
different rounds.

Glint runs as `glint render SCENE --integrator path --spp N --seed S -w 256 -h 256 -o OUT.exr`.

Usage: bench/cornell_vs_mitsuba.py [--repeats 5] [--skip-setup]
Needs: ../shared/bench/setup-peers.sh (run first unless --skip-setup), cargo.
"""

import argparse
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.normpath(os.path.join(ROOT, "..", "shared"))
SCENE = os.path.join(SHARED, "refs", "cornell", "cornell.json")
REFERENCE = os.path.join(SHARED, "refs", "cornell", "mitsuba_256_4096spp.exr")
REFERENCE_SPP = 4096
MITSUBA_SPP = 64
SIZE = 256


def run(cmd, **kwargs):
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kwargs)


def read_exr(path):
    import mitsuba as mi
    import numpy as np

    return np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3]


def relative_mse(image, reference):
    return float(((image - reference) ** 2 / (reference**2 + 0.01)).mean())


# Runs make_cornell_ref.py (argv[1:]) unchanged, with time.time kept: the script times
# `mi.render(mi.load_dict(scene))` between its two calls of time.time() (the render itself runs
# when Dr.Jit evaluates the image, inside that interval) and prints the difference to 0.1 s
# only; this prints it in full. Anything else calling time.time() makes the line absent.
PRECISE_TIMER = """
import runpy, sys, time
import mitsuba  # imported (and its own timers set up) before time.time is watched
calls, clock = [], time.time
def timed():
    calls.append(clock())
    return calls[-1]
time.time = timed
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name='__main__')
if len(calls) == 2:
    print(f'precise: {calls[1] - calls[0]:.4f} s')
"""


def run_mitsuba(out_dir):
    """Renders the 64-spp image and returns Mitsuba's own timing of it (load_dict + render,
    as make_cornell_ref.py measures it, read at full precision), the wall time of its whole
    process (Python start, import, scene construction, render, EXR and PNG write) and the
    EXR's path."""
    start = time.perf_counter()
    result = run(
        [
            sys.executable,
            "-c",
            PRECISE_TIMER,
            os.path.join(SHARED, "bench", "make_cornell_ref.py"),
            "--spp",
            str(MITSUBA_SPP),
            "--size",
            str(SIZE),
            "--out",
            out_dir,
        ]
    )
    process_seconds = time.perf_counter() - start
    precise = re.search(r"precise: ([0-9.]+) s", result.stdout)
    if precise is None:
        sys.exit(
            "make_cornell_ref.py called time.time() other than twice: no precise timing"
        )
    seconds = float(precise.group(1))
    return (
        seconds,
        process_seconds,
        os.path.join(out_dir, f"mitsuba_{SIZE}_{MITSUBA_SPP}spp.exr"),
    )


class Glint:
    """Runs Glint's path tracer on the Cornell box through the release CLI."""

    def __init__(self):
        run(["cargo", "build", "--release", "--quiet", "-p", "glint"], cwd=ROOT)
        self.cli = os.path.join(ROOT, "target", "release", "glint")
        self.how = "glint CLI"

    def render(self, spp, seed, out):
        """Renders and returns the process's wall time."""
        command = [
            self.cli,
            "render",
            SCENE,
            "--integrator",
            "path",
            "--spp",
            str(spp),
            "--seed",
            str(seed),
            "-w",
            str(SIZE),
            "-h",
            str(SIZE),
            "-o",
            out,
        ]
        start = time.perf_counter()
        run(command)
        return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--skip-setup", action="store_true")
    args = ap.parse_args()
    if not args.skip_setup:
        subprocess.run(
            ["bash", os.path.join(SHARED, "bench", "setup-peers.sh")],
            check=True,
            stdout=subprocess.DEVNULL,
        )
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    reference = read_exr(REFERENCE)
    work = tempfile.mkdtemp(prefix="cornell_bench_")
    try:
        # The first run also compiles Dr.Jit's kernels (later runs find them cached); its image
        # sets the target error.
        first_seconds, _first_process_seconds, mitsuba_exr = run_mitsuba(work)
        target = relative_mse(read_exr(mitsuba_exr), reference)
        # Mitsuba's error is a_M (1/64 + 1/4096) for per-sample variance a_M; the reference's
        # share of every error measured against it is c = a_M / 4096.
        reference_noise = (
            target / (1 + MITSUBA_SPP / REFERENCE_SPP) * MITSUBA_SPP / REFERENCE_SPP
        )

        glint = Glint()
        probe_exr = os.path.join(work, "glint_probe.exr")
        glint.render(MITSUBA_SPP, 1, probe_exr)
        probe = relative_mse(read_exr(probe_exr), reference)
        spp = max(
            1,
            math.ceil(
                MITSUBA_SPP
                * max(probe - reference_noise, 1e-12)
                / max(target - reference_noise, 1e-12)
            ),
        )
        tried = []
        while True:
            out = os.path.join(work, f"glint_{spp}.exr")
            glint.render(spp, 1, out)
            error = relative_mse(read_exr(out), reference)
            tried.append((spp, error))
            if error <= target or len(tried) >= 12:
                break
            spp = math.ceil(spp * 1.05)
        # Timed runs alternate between the two renderers, so a change in the machine's load
        # hits both; each keeps its best time.
        # The first Mitsuba process also compiled the kernels: only its render-only time,
        # which Mitsuba's kernel cache makes comparable, enters.
        mitsuba_seconds, glint_seconds = first_seconds, math.inf
        mitsuba_process_seconds = math.inf
        round_ratios = []
        for _ in range(args.repeats):
            seconds, process_seconds, _ = run_mitsuba(work)
            mitsuba_seconds = min(mitsuba_seconds, seconds)
            mitsuba_process_seconds = min(mitsuba_process_seconds, process_seconds)
            glint_round = glint.render(spp, 1, os.path.join(work, "timed.exr"))
            glint_seconds = min(glint_seconds, glint_round)
            round_ratios.append(glint_round / seconds)
    finally:
        shutil.rmtree(work, ignore_errors=True)

    reached = tried[-1][1] <= target
    print(
        f"Cornell box {SIZE}x{SIZE}, 2 cores, best of {args.repeats}; relMSE against "
        f"Mitsuba {REFERENCE_SPP} spp (includes its noise, ~{reference_noise:.2e})"
    )
    print(
        f"  Mitsuba 3 {mi.__version__} llvm_ad_rgb, {MITSUBA_SPP} spp: relMSE {target:.4e}, "
        f"{mitsuba_seconds:.3f} s (load_dict + render); whole process "
        f"{mitsuba_process_seconds:.2f} s"
    )
    print(
        f"  Glint ({glint.how}): probe {MITSUBA_SPP} spp relMSE {probe:.4e}; tried "
        + ", ".join(f"{s} spp -> {e:.4e}" for s, e in tried)
    )
    print(
        f"  Glint, {spp} spp: relMSE {tried[-1][1]:.4e}, {glint_seconds:.3f} s"
        + ("" if reached else "  (did NOT reach the target)")
    )
    print(
        f"time ratio Glint / Mitsuba at equal error: {glint_seconds / mitsuba_seconds:.3f} "
        f"(Glint's whole process against Mitsuba's render-only time)"
    )
    print(
        f"  whole process against whole process: "
        f"{glint_seconds / mitsuba_process_seconds:.3f}"
    )
    print(
        f"  round by round (Glint's run / the Mitsuba run before it): median "
        f"{statistics.median(round_ratios):.3f}, from {min(round_ratios):.3f} to "
        f"{max(round_ratios):.3f}"
    )


if __name__ == "__main__":
    main()
