#!/usr/bin/env python3
"""Clean images sooner: error against time for plain, adaptive, denoised and
adaptive+denoised path tracing, on the Cornell box of ../shared/refs/cornell (against
Mitsuba's 4096-spp render) and on a harder scene (scenes/mitsuba/cornell-rough.xml: rough
gold and rough glass, against Glint's own 4096-spp render, made once and kept in --refs).

Each configuration is one `glint render` process; its time is the wall time of the process
(load, render, denoise, write), the median of --rounds alternating rounds, each round running
every configuration once in a rotated order. Its error is measured once (the image does not
change between rounds: the seed is fixed): relative MSE (the test suite's: the mean over
pixels and channels of (x - r)^2 / (r^2 + 0.01)) and the mean of LDR-FLIP (`glint diff`).

    GLINT_OIDN_LIB=... python3 bench/clean_images.py --glint target/release/glint \
        --out /tmp/clean --refs bench/refs --plot docs/clean-images.png

Needs numpy, OpenEXR and matplotlib (for --plot). Prints a Markdown table per scene and the
target's verdict: the quality of 1024 plain samples (both figures) in at most a tenth of
their time.
"""

import argparse
import json
import re
import statistics
import subprocess
import time
from pathlib import Path

import numpy as np
import OpenEXR

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared"

SCENES = {
    "cornell": {
        "scene": SHARED / "refs/cornell/cornell.json",
        "args": ["--integrator", "path", "-w", "256", "-h", "256"],
        "reference": SHARED / "refs/cornell/mitsuba_256_4096spp.exr",
    },
    "cornell-rough": {
        "scene": ROOT / "scenes/mitsuba/cornell-rough.xml",
        "args": ["-w", "256", "-h", "256"],
        "reference": None,
    },
}

# (method, label, extra arguments); 1024 plain samples are the quality to reach.
CONFIGS = (
    [("plain", f"plain-{n}", ["--spp", str(n)]) for n in (16, 64, 256, 1024)]
    + [
        ("adaptive", f"adaptive-{t}", ["--spp", "1024", "--noise-threshold", str(t)])
        for t in (0.1, 0.05, 0.03)
    ]
    + [
        ("denoised", f"denoised-{n}", ["--spp", str(n), "--denoise"])
        for n in (4, 16, 64)
    ]
    + [
        (
            "adaptive+denoised",
            f"adaptive+denoised-{t}",
            ["--spp", "1024", "--noise-threshold", str(t), "--denoise"],
        )
        for t in (0.2, 0.1)
    ]
)


def read_rgb(path):
    channels = OpenEXR.File(str(path)).channels()
    if "RGB" in channels:
        return np.asarray(channels["RGB"].pixels, dtype=np.float64)
    return np.stack(
        [np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], -1
    )


def relative_mse(image, reference):
    return float(np.mean((image - reference) ** 2 / (reference**2 + 0.01)))


def flip(glint, reference, image):
    out = subprocess.run(
        [glint, "diff", str(reference), str(image)],
        check=False,
        capture_output=True,
        text=True,
    )
    found = re.search(r"FLIP: mean ([0-9.]+)", out.stdout + out.stderr)
    if not found:
        raise RuntimeError(f"glint diff printed no FLIP: {out.stdout}{out.stderr}")
    return float(found.group(1))


def render(glint, scene, args, output):
    start = time.perf_counter()
    run = subprocess.run(
        [
            glint,
            "render",
            str(scene["scene"]),
            *scene["args"],
            *args,
            "-o",
            str(output),
        ],
        check=False,
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - start
    if run.returncode != 0:
        raise RuntimeError(f"glint render {args} failed: {run.stderr}")
    samples = re.search(r"adaptive sampling: ([0-9.]+) samples per pixel", run.stderr)
    return seconds, float(samples.group(1)) if samples else None


def reference_for(glint, name, scene, refs):
    if scene["reference"] is not None:
        return scene["reference"]
    path = refs / f"{name}-4096spp.exr"
    if not path.exists():
        refs.mkdir(parents=True, exist_ok=True)
        print(f"making {path} (4096 spp)", flush=True)
        render(glint, scene, ["--spp", "4096", "--seed", "4096"], path)
    return path


def campaign(glint, name, scene, out, refs, rounds):
    reference_path = reference_for(glint, name, scene, refs)
    reference = read_rgb(reference_path)
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    times = {label: [] for _, label, _ in CONFIGS}
    samples = {}
    for r in range(rounds):
        shift = r * len(CONFIGS) // rounds
        for method, label, args in CONFIGS[shift:] + CONFIGS[:shift]:
            seconds, mean_samples = render(glint, scene, args, folder / f"{label}.exr")
            times[label].append(seconds)
            samples[label] = mean_samples
            print(f"{name} round {r + 1} {label}: {seconds:.2f} s", flush=True)
    rows = []
    for method, label, _ in CONFIGS:
        image = folder / f"{label}.exr"
        rows.append(
            {
                "method": method,
                "label": label,
                "seconds": statistics.median(times[label]),
                "rel_mse": relative_mse(read_rgb(image), reference),
                "flip": flip(glint, reference_path, image),
                "samples": samples[label],
            }
        )
    return rows


def verdict(rows):
    plain = next(row for row in rows if row["label"] == "plain-1024")
    lines = []
    for method in ("adaptive", "denoised", "adaptive+denoised"):
        good = [
            row
            for row in rows
            if row["method"] == method
            and row["rel_mse"] <= plain["rel_mse"]
            and row["flip"] <= plain["flip"]
        ]
        if not good:
            lines.append(
                f"- {method}: no configuration reaches plain 1024's relMSE and FLIP"
            )
            continue
        best = min(good, key=lambda row: row["seconds"])
        ratio = best["seconds"] / plain["seconds"]
        met = "met" if ratio <= 0.1 else "not met"
        lines.append(
            f"- {method}: {best['label']} reaches it in {best['seconds']:.2f} s, "
            f"{ratio:.3f} of plain 1024's {plain['seconds']:.2f} s ({met})"
        )
    return "\n".join(lines)


def table(name, rows):
    lines = [
        f"### {name}",
        "",
        "| configuration | time (s) | mean spp | relMSE | mean FLIP |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        spp = f"{row['samples']:.1f}" if row["samples"] is not None else ""
        lines.append(
            f"| {row['label']} | {row['seconds']:.2f} | {spp} | {row['rel_mse']:.3e} "
            f"| {row['flip']:.4f} |"
        )
    return "\n".join(lines) + "\n\n" + verdict(rows)


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(
        2, len(results), figsize=(6 * len(results), 8), squeeze=False
    )
    markers = {"plain": "o", "adaptive": "s", "denoised": "^", "adaptive+denoised": "D"}
    for column, (name, rows) in enumerate(results.items()):
        for row_index, (key, title) in enumerate(
            (("rel_mse", "relative MSE"), ("flip", "mean FLIP"))
        ):
            axis = axes[row_index][column]
            for method, marker in markers.items():
                points = sorted(
                    (row["seconds"], row[key])
                    for row in rows
                    if row["method"] == method
                )
                if points:
                    axis.plot(*zip(*points), marker=marker, label=method)
            plain = next(row for row in rows if row["label"] == "plain-1024")
            axis.axhline(plain[key], color="grey", linestyle=":", linewidth=1)
            axis.axvline(
                plain["seconds"] / 10, color="grey", linestyle="--", linewidth=1
            )
            axis.set_xscale("log")
            axis.set_yscale("log")
            axis.set_xlabel("seconds (2 cores)")
            axis.set_ylabel(title)
            axis.set_title(f"{name}: {title}")
            axis.grid(True, which="both", alpha=0.3)
            axis.legend(fontsize="small")
    figure.suptitle(
        "Error against time; dotted: plain 1024 spp's error, dashed: a tenth of its time"
    )
    figure.tight_layout()
    figure.savefig(path, dpi=90)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--glint", default=str(ROOT / "target/release/glint"))
    parser.add_argument("--out", type=Path, default=Path("/tmp/glint-clean-images"))
    parser.add_argument("--refs", type=Path, default=ROOT / "bench/refs")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--plot", type=Path)
    parser.add_argument(
        "--reuse",
        action="store_true",
        help="take a scene's figures from OUT/SCENE/results.json when an earlier run left it",
    )
    options = parser.parse_args()
    results = {}
    for name in options.scenes.split(","):
        saved = options.out / name / "results.json"
        if options.reuse and saved.exists():
            results[name] = json.loads(saved.read_text())
        else:
            results[name] = campaign(
                options.glint,
                name,
                SCENES[name],
                options.out,
                options.refs,
                options.rounds,
            )
            saved.write_text(json.dumps(results[name], indent=1))
        print(table(name, results[name]), flush=True)
    if options.plot:
        plot(results, options.plot)


if __name__ == "__main__":
    main()
