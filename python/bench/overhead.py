"""glint.render against the `glint` CLI on the same render, in alternating rounds.

    python bench/overhead.py [--cli target/release/glint] [--rounds 5] [SCENE]

Each round runs the CLI (`glint render SCENE -o x.png ...`) and then `glint.render` in a fresh
Python process, with the same settings and threads. It compares
  - the render itself: the CLI's own timing of `glint_render::render` (its closing line,
    "rendered ... in X s") against the wall time of the `glint.render(...)` call, which includes
    everything the module adds (argument checks, the helper thread, the polling, the copy into
    numpy);
  - the whole process: `glint render ...` against `python -c "import glint; load; render;
    write_image"` (adds the interpreter's and numpy's start-up);
  - CPU time (user + system, all threads), which other processes' load disturbs much less
    than wall time: the CLI's whole process against the `glint.render(...)` call, and the
    whole processes.
and prints the median of each over the rounds and the ratio of the medians.
"""

from __future__ import annotations

import argparse
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

CHILD = r"""
import sys, time
import glint
scene = glint.load_scene(sys.argv[1])
w, h, spp, threads = (int(sys.argv[i]) for i in (2, 3, 4, 6))
t, cpu = time.perf_counter(), time.process_time()
image = glint.render(scene, width=w, height=h, spp=spp, integrator=sys.argv[5], threads=threads)
render, cpu = time.perf_counter() - t, time.process_time() - cpu
glint.write_image(sys.argv[7], image)
print(render, cpu)
"""


def children_cpu() -> float:
    """User + system CPU seconds of the finished child processes so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("scene", nargs="?", default=str(REPO / "scenes" / "three_spheres.xml"))
    parser.add_argument("--cli", default=str(REPO / "target" / "release" / "glint"))
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--width", type=int, default=400)
    parser.add_argument("--height", type=int, default=300)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--integrator", default="path")
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()

    settings = [str(args.width), str(args.height), str(args.spp), args.integrator]
    cli_render, cli_wall, py_render, py_wall = [], [], [], []
    cli_cpu, py_cpu, py_process_cpu = [], [], []
    with tempfile.TemporaryDirectory() as folder:
        for round_ in range(args.rounds):
            command = [args.cli, "render", args.scene, "-o", f"{folder}/cli.png"]
            command += ["-w", settings[0], "-h", settings[1], "-r", settings[2]]
            command += ["--integrator", args.integrator, "-n", str(args.threads)]
            start, used = time.perf_counter(), children_cpu()
            result = subprocess.run(command, capture_output=True, text=True, check=True)
            cli_wall.append(time.perf_counter() - start)
            cli_cpu.append(children_cpu() - used)
            cli_render.append(float(re.search(r" in ([0-9.]+) s:", result.stderr).group(1)))

            command = [sys.executable, "-c", CHILD, args.scene, *settings, str(args.threads)]
            command.append(f"{folder}/py.png")
            start, used = time.perf_counter(), children_cpu()
            # From the temporary folder: `import glint` is the installed module, not python/glint.
            result = subprocess.run(command, capture_output=True, text=True, check=True, cwd=folder)
            py_wall.append(time.perf_counter() - start)
            py_process_cpu.append(children_cpu() - used)
            render, cpu = result.stdout.split()
            py_render.append(float(render))
            py_cpu.append(float(cpu))
            print(
                f"round {round_ + 1}: render cli {cli_render[-1]:.2f} s, python "
                f"{py_render[-1]:.3f} s; process cli {cli_wall[-1]:.2f} s, "
                f"python {py_wall[-1]:.2f} s; cpu cli {cli_cpu[-1]:.2f} s, python render "
                f"{py_cpu[-1]:.2f} s, python process {py_process_cpu[-1]:.2f} s",
                flush=True,
            )
    for what, cli, py in (
        ("render (wall)", cli_render, py_render),
        ("process (wall)", cli_wall, py_wall),
        ("cli process / python render call (cpu)", cli_cpu, py_cpu),
        ("process (cpu)", cli_cpu, py_process_cpu),
    ):
        c, p = statistics.median(cli), statistics.median(py)
        print(f"{what}: median cli {c:.3f} s, python {p:.3f} s, python/cli {p / c:.3f}")


if __name__ == "__main__":
    main()
