#!/usr/bin/env python3
"""Glint's GPU against Mitsuba 3's CUDA and LLVM variants and Glint's CPU, scene by scene.

Renderers (columns): `glint render --device gpu`; Mitsuba 3 `cuda_ad_rgb` and `llvm_ad_rgb`
(pip `mitsuba`, as ../shared/bench/setup-peers.sh installs it); `glint render` on the CPU with
`-n THREADS` (default 16). Scenes (rows): Mitsuba's Cornell box (`mitsuba/scenes/cbox/cbox.xml`,
which both load; `res` and `spp` set as each renderer's parameters, 512 and 1024 by default);
the surface scenes of Mitsuba's test suite (integrator `path`, `direct` or `ptracer`) at its
rule's sample count, 2,000,000 / pixels; and a large mesh, `models/igea-sub4.ply` (1,074,744
triangles), diffuse under a rectangular area light, at 512x512 and 1024 spp (the scene file is
written by this script, the same file for both renderers).

Every render is its own process; the renderers take turns within each round, in reverse order
every other round, and each cell is the median over `--rounds` rounds. Two tables, each with
the ratio to `cuda_ad_rgb`'s median (below 1: faster than Mitsuba on CUDA):

- render: Glint's own render time (the `rendered ... in S s` line, 0.01 s resolution; on the
  GPU it includes flattening the scene, building its BVH and uploading the buffers, not opening
  the device or compiling the kernel); Mitsuba's `mi.render` alone, timed on a second render
  in the same process after an untimed first one that compiles its kernels (as Mitsuba's docs
  advise), its image evaluated (`dr.eval`, `dr.sync_thread`) inside the timing.
- whole: the process from its start to its image: Glint's load, device and kernel compile (on
  the GPU), render and write; Mitsuba's Python start, import, `set_variant`, `mi.load_file`
  and the first render, compile included (to the moment it ends, not the second render).

A variant that cannot be set here (no CUDA, no LLVM) is "not available" in its column; a scene
a renderer refuses (exit 2, as glint's GPU does for what its kernel lacks) is "refused"; any
other failure is "failed". Neither stops the script.

    python3 bench/device/gpu-timing.py --glint target/release/glint [--rounds 3]
        [--python PY] [--threads 16] [--spp N] [--size N] [--only TEXT] [--out FILE]

`--python` (or $GLINT_MITSUBA_PYTHON; default python3) is the interpreter that has mitsuba.
`--spp N` renders every scene at N samples per pixel, `--size N` the Cornell box and the mesh
at NxN (the suite's scenes keep their references' size): for a quick smoke test.
"""

import argparse
import json
import os
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
BUDGET = 2_000_000
RENDERERS = ["glint gpu", "cuda_ad_rgb", "llvm_ad_rgb", "glint cpu"]
BASELINE = "cuda_ad_rgb"

# One Mitsuba render in its own process. Exit 3: the variant cannot be set here. Prints one
# JSON line: the monotonic clock (shared by all processes on Linux) when the first, compiling
# render ended, the load's and the second render's seconds.
MITSUBA_WORKER = r"""
import json, sys, time
try:
    import drjit as dr
    import mitsuba as mi
    mi.set_variant(sys.argv[1])
except Exception as error:
    print(f"variant {sys.argv[1]}: {error}", file=sys.stderr)
    sys.exit(3)
scene_path, spp = sys.argv[2], int(sys.argv[3])
params = json.loads(sys.argv[4])
def render(scene, seed):
    image = mi.render(scene, spp=spp, seed=seed)
    dr.eval(image)
    dr.sync_thread()
start = time.perf_counter()
scene = mi.load_file(scene_path, **params)
load = time.perf_counter() - start
render(scene, 0)
first_end = time.monotonic()
start = time.perf_counter()
render(scene, 1)
print(json.dumps({"first_end": first_end, "load": load, "render": time.perf_counter() - start}))
"""

MESH_SCENE = """<scene version="3.0.0">
    <default name="spp" value="1024"/>
    <default name="res" value="512"/>
    <integrator type="path">
        <integer name="max_depth" value="6"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world">
            <lookat origin="0, 0.02, 0.3" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <shape type="ply">
        <string name="filename" value="{mesh}"/>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.7, 0.7, 0.7"/>
        </bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="0.05"/>
            <rotate x="1" angle="90"/>
            <translate value="0, 0.15, 0.1"/>
        </transform>
        <emitter type="area">
            <rgb name="radiance" value="20, 20, 20"/>
        </emitter>
    </shape>
</scene>
"""


class Scene:
    """A row: a scene file, its sample count and the parameters (`-D` / `load_file`)."""

    def __init__(self, name, path, spp, params):
        self.name, self.path, self.spp, self.params = name, path, spp, params


def exr_size(path):
    """Width and height from an OpenEXR header's dataWindow (box2i)."""
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    at = 8  # magic and version
    while data[at] != 0:
        name_end = data.index(b"\0", at)
        kind_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack("<i", data[kind_end + 1 : kind_end + 5])
        value = data[kind_end + 5 : kind_end + 5 + size]
        if data[at:name_end] == b"dataWindow":
            x0, y0, x1, y1 = struct.unpack("<4i", value)
            return x1 - x0 + 1, y1 - y0 + 1
        at = kind_end + 5 + size
    raise ValueError(f"{path}: no dataWindow")


def suite_scenes(shared, spp_override):
    """The suite's surface scenes by their integrator suffix, at the rule's sample count."""
    suite = shared / "mitsuba" / "tests" / "scenes"
    for scene in sorted(suite.glob("*/*.xml")):
        stem, integrator = scene.stem.rsplit("_", 1)
        if integrator not in ("path", "direct", "ptracer"):
            continue
        width, height = exr_size(scene.parent / "refs" / f"{stem}_ref_rgb.exr")
        spp = spp_override or max(1, BUDGET // (width * height))
        yield Scene(f"{scene.parent.name}/{scene.stem}", scene, spp, {})


def all_scenes(shared, work, spp, size):
    res = size or 512
    cbox = shared / "mitsuba" / "scenes" / "cbox" / "cbox.xml"
    yield Scene(f"cbox {res}x{res}", cbox, spp or 1024, {"res": res})
    yield from suite_scenes(shared, spp)
    mesh = work / "igea_sub4.xml"
    mesh.write_text(
        MESH_SCENE.replace("{mesh}", str(shared / "models" / "igea-sub4.ply"))
    )
    yield Scene(f"igea-sub4 mesh {res}x{res}", mesh, spp or 1024, {"res": res})


def llvm_environment(env):
    """Dr.Jit's LLVM back end needs LLVM 19: Debian's libllvm19 where ldconfig finds it and
    DRJIT_LIBLLVM_PATH names none (as bench/mitsuba_suite.py does)."""
    if "DRJIT_LIBLLVM_PATH" in env:
        return env
    listing = subprocess.run(
        ["ldconfig", "-p"], check=False, capture_output=True, text=True
    )
    for line in listing.stdout.splitlines():
        if "libLLVM.so.19" in line and "=>" in line:
            env["DRJIT_LIBLLVM_PATH"] = line.split("=>")[1].strip()
            break
    return env


def run_glint(args, device, scene, out):
    """(whole, render) seconds, or a word for the cell."""
    cmd = [
        args.glint,
        "render",
        str(scene.path),
        "-o",
        str(out),
        "--spp",
        str(scene.spp),
    ]
    for name, value in scene.params.items():
        cmd += ["-D", f"{name}={value}"]
    cmd += ["--device", "gpu"] if device == "gpu" else ["-n", str(args.threads)]
    start = time.monotonic()
    try:
        proc = subprocess.run(
            cmd, check=False, capture_output=True, text=True, timeout=args.timeout
        )
    except subprocess.TimeoutExpired:
        return "timed out"
    whole = time.monotonic() - start
    if proc.returncode != 0:
        note(scene, f"glint {device}", proc.stderr)
        return "refused" if proc.returncode == 2 else f"failed ({proc.returncode})"
    found = re.search(
        r"^rendered .* in ([0-9.]+) s", proc.stderr + proc.stdout, re.MULTILINE
    )
    if not found:
        note(scene, f"glint {device}", "no `rendered ... in S s` line")
        return "failed"
    return whole, float(found.group(1))


def run_mitsuba(args, variant, scene, env):
    """(whole, render) seconds, or a word for the cell."""
    cmd = [args.python, "-c", MITSUBA_WORKER, variant, str(scene.path), str(scene.spp)]
    cmd.append(json.dumps({k: str(v) for k, v in scene.params.items()}))
    start = time.monotonic()
    try:
        proc = subprocess.run(
            cmd,
            check=False,
            capture_output=True,
            text=True,
            timeout=args.timeout,
            env=env,
        )
    except subprocess.TimeoutExpired:
        return "timed out"
    except OSError as error:  # no such interpreter
        note(scene, variant, str(error))
        return "not available"
    if proc.returncode == 3:
        return "not available"
    try:
        times = json.loads(proc.stdout.strip().splitlines()[-1])
    except (IndexError, ValueError):
        note(scene, variant, proc.stderr)
        return f"failed ({proc.returncode})"
    return times["first_end"] - start, times["render"]


NOTED = set()


def note(scene, renderer, stderr):
    """A failed render's last line, once per scene and renderer (not every round)."""
    lines = [line for line in stderr.strip().splitlines() if line.strip()]
    line = f"  {scene.name}, {renderer}: {lines[-1] if lines else 'no message'}"
    if line not in NOTED:
        NOTED.add(line)
        print(line, flush=True)


def cell(value, baseline):
    if isinstance(value, str):
        return value
    if isinstance(baseline, str):
        return f"{value:.3f}"
    return f"{value:.3f} ({value / baseline:.2f}x)"


def table(title, rows, index):
    lines = [f"### {title}", "", "| scene | spp | " + " | ".join(RENDERERS) + " |"]
    lines.append("|---|---:|" + "---:|" * len(RENDERERS))
    for scene, medians in rows:
        values = {r: m if isinstance(m, str) else m[index] for r, m in medians.items()}
        cells = [cell(values[r], values[BASELINE]) for r in RENDERERS]
        lines.append(f"| {scene.name} | {scene.spp} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def median_of(results):
    """Medians of (whole, render) over the rounds; a word when any round has none."""
    words = [r for r in results if isinstance(r, str)]
    if words:
        return words[0]
    return tuple(statistics.median(r[i] for r in results) for i in (0, 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--glint", default=str(ROOT / "target" / "release" / "glint"))
    ap.add_argument("--shared", default=str(ROOT.parent / "shared"))
    ap.add_argument(
        "--python", default=os.environ.get("GLINT_MITSUBA_PYTHON", "python3")
    )
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=16)
    ap.add_argument(
        "--spp", type=int, default=None, help="every scene's spp (a smoke test)"
    )
    ap.add_argument(
        "--size", type=int, default=None, help="side of the Cornell box and mesh"
    )
    ap.add_argument(
        "--only", default=None, help="only the scenes whose name contains TEXT"
    )
    ap.add_argument(
        "--timeout", type=float, default=300, help="seconds one render may take"
    )
    ap.add_argument("--out", default="gpu-timing.md", help="the Markdown table's file")
    args = ap.parse_args()
    if not os.access(args.glint, os.X_OK):
        sys.exit(
            f"no executable glint at {args.glint} (cargo build --release -p glint)"
        )
    env = llvm_environment(dict(os.environ))
    rows = []
    missing = set()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        scenes = all_scenes(Path(args.shared), work, args.spp, args.size)
        for scene in scenes:
            if args.only and args.only not in scene.name:
                continue
            results = {r: [] for r in RENDERERS}
            for round_ in range(args.rounds):
                order = RENDERERS if round_ % 2 == 0 else RENDERERS[::-1]
                for renderer in order:
                    if renderer in missing:
                        result = "not available"
                    elif renderer.startswith("glint"):
                        device = renderer.split()[1]
                        result = run_glint(args, device, scene, work / "out.exr")
                    else:
                        result = run_mitsuba(args, renderer, scene, env)
                        if result == "not available":
                            missing.add(renderer)  # not asked again, scene after scene
                    results[renderer].append(result)
            medians = {r: median_of(v) for r, v in results.items()}
            rows.append((scene, medians))
            summary = ", ".join(
                f"{r} {m if isinstance(m, str) else f'{m[1]:.3f} s'}"
                for r, m in medians.items()
            )
            print(f"{scene.name}: {summary}", flush=True)
    if not rows:
        sys.exit("no scene matched")
    report = "\n\n".join(
        [
            (
                f"GPU timing: medians of {args.rounds} rounds, seconds (ratio to "
                f"{BASELINE}); glint cpu at {args.threads} threads."
            ),
            table("render", rows, 1),
            table("whole process", rows, 0),
        ]
    )
    print()
    print(report)
    Path(args.out).write_text(report + "\n")


if __name__ == "__main__":
    main()
