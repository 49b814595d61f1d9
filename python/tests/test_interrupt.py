"""Progress, Ctrl-C and the GIL while rendering."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from conftest import THREE_SPHERES

import glint

# A render long enough to interrupt (1024 tiles, 67 M path-traced samples): the tests stop it
# early.
LONG = dict(width=512, height=512, spp=256, integrator="path", threads=2)


def test_progress_rises_to_one_and_is_throttled():
    scene = glint.load_scene(THREE_SPHERES)
    seen: list[tuple[float, float]] = []
    threads = set()

    def progress(fraction: float) -> None:
        threads.add(threading.get_ident())
        seen.append((time.perf_counter(), fraction))

    start = time.perf_counter()
    glint.render(scene, width=160, height=160, spp=16, integrator="path", progress=progress)
    elapsed = time.perf_counter() - start
    fractions = [f for _, f in seen]
    assert fractions[-1] == 1.0
    assert threads == {threading.get_ident()}, "called on the caller's thread only"
    assert fractions == sorted(fractions)
    assert all(0.0 <= f <= 1.0 for f in fractions)
    assert len(set(fractions)) == len(fractions), "each report says something new"
    # 100 tiles, but at most one report per 0.1 s polling interval (plus the last).
    assert len(fractions) <= elapsed / 0.1 + 2
    gaps = [later - earlier for (earlier, _), (later, _) in zip(seen, seen[1:-1])]
    assert all(gap > 0.09 for gap in gaps), gaps


def test_an_exception_in_progress_stops_the_render():
    scene = glint.load_scene(THREE_SPHERES)
    calls = []

    def stop(fraction: float) -> None:
        calls.append(fraction)
        if fraction > 0:
            raise RuntimeError("enough")

    start = time.perf_counter()
    with pytest.raises(RuntimeError, match="enough"):
        glint.render(scene, progress=stop, **LONG)
    assert time.perf_counter() - start < 10
    assert 0 < calls[-1] < 0.5


def test_the_gil_is_released_while_rendering():
    scene = glint.load_scene(THREE_SPHERES)
    done = threading.Event()
    rendered = []

    def work():
        rendered.append(
            glint.render(scene, width=128, height=128, spp=64, integrator="path", threads=1)
        )
        done.set()

    thread = threading.Thread(target=work)
    start = time.perf_counter()
    thread.start()
    count = 0
    while not done.is_set():
        count += 1
    thread.join()
    elapsed = time.perf_counter() - start
    assert rendered[0].shape == (128, 128, 3)
    # Python kept running here the whole time: a held GIL would have kept `count` near zero.
    assert elapsed > 0.2
    assert count > 100_000 * elapsed


# The child restores Python's own SIGINT handler: a process started in the background by a
# non-interactive shell (as a CI job may be) inherits SIGINT ignored, and Python then installs no
# KeyboardInterrupt at all; an interactive session always has it.
CHILD = r"""
import signal, sys, time, glint
signal.signal(signal.SIGINT, signal.default_int_handler)
scene = glint.load_scene(sys.argv[1])
def progress(fraction):
    print(f"progress {fraction} {time.perf_counter()}", flush=True)
try:
    glint.render(scene, progress=progress, **eval(sys.argv[2]))
except KeyboardInterrupt:
    print(f"interrupted {time.perf_counter()}", flush=True)
    sys.exit(3)
print("finished", flush=True)
"""


def test_ctrl_c_raises_keyboard_interrupt_within_a_tile():
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(THREE_SPHERES), repr(LONG)],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        # Wait until tiles are being finished, then press Ctrl-C.
        fraction = 0.0
        while fraction == 0.0:
            line = child.stdout.readline()
            assert line.startswith("progress"), line
            fraction = float(line.split()[1])
        sent = time.perf_counter()
        os.kill(child.pid, signal.SIGINT)
        rest = child.stdout.read().split("\n")
        child.wait(timeout=60)
    finally:
        child.kill()
    assert child.returncode == 3, rest
    stopped = float([line for line in rest if line.startswith("interrupted")][0].split()[1])
    last = [float(line.split()[1]) for line in rest if line.startswith("progress")]
    # It stopped early (the render was far from done) and soon: a 16x16 tile of 256
    # path-traced samples takes tens of milliseconds, plus the 0.1 s polling interval.
    assert max(last, default=fraction) < 0.5
    assert stopped - sent < 2.0
