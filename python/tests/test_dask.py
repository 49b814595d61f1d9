"""Tiles of one frame as Dask tasks on two worker processes: the single-process image, bit for
bit (the code is examples/dask_tiles.py, which the README points to)."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest
from conftest import THREE_SPHERES

import glint

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dask_tiles.py"


def load_example():
    spec = importlib.util.spec_from_file_location("dask_tiles", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_dask_tiles_on_two_processes_give_the_single_process_image():
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        if os.environ.get("CI"):
            raise
        pytest.skip("SKIPPED: dask.distributed is not installed")
    scene = glint.load_scene(THREE_SPHERES)
    settings = dict(spp=4, integrator="path", seed=21, threads=1)
    width, height = 100, 70  # tiles of 32: ragged at the right and bottom edges
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        frame = load_example().render_tiles(client, scene, width, height, tile=32, **settings)
        # The tasks really ran in the two worker processes, not here.
        pids = client.run(os.getpid)
        assert len(set(pids.values())) == 2 and os.getpid() not in pids.values()
    single = glint.render(scene, width=width, height=height, **settings)
    assert np.array_equal(frame.view(np.uint32), single.view(np.uint32))
    assert frame.std() > 0.01
