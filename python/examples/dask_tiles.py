"""Render one frame as tiles on a Dask cluster and put it together.

    python examples/dask_tiles.py SCENE [--width W --height H --spp N --tile T --workers K]

Size, samples and integrator not given are the scene's, as for `glint.render` and the CLI (a
Mitsuba scene's film, sampler and integrator; a course scene's 100 x 100, 1 sample, `course`).

Each tile is one task: `glint.render(scene, crop=tile, ...)` on whichever worker Dask picks.
The scene is sent to the workers once (`client.scatter`); a `glint.Scene` pickles as where it
came from and each worker loads it again, so the workers need the scene's files (a shared file
system on a real cluster). Pixels depend only on (seed, pixel, sample), so the assembled image
is the single-process image, bit for bit.

With `--compare` it also renders the frame in this process and prints both wall times.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import glint


def render_tiles(client, scene, width=None, height=None, tile=64, **settings) -> np.ndarray:
    """Renders `scene` as tiles on the Dask `client`'s workers and assembles the frame; a size
    not given is the scene's own, as for `glint.render`."""
    settled = scene.render_settings(width=width, height=height)
    width, height = settled["width"], settled["height"]
    [remote_scene] = client.scatter([scene], broadcast=True)
    crops = glint.tiles(width, height, size=tile)
    futures = [
        client.submit(
            glint.render,
            remote_scene,
            width=width,
            height=height,
            crop=crop,
            pure=False,
            **settings,
        )
        for crop in crops
    ]
    frame = np.zeros((height, width, 3), np.float32)
    for crop, pixels in zip(crops, client.gather(futures)):
        frame[crop] = pixels
    return frame


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--width", type=int)
    parser.add_argument("--height", type=int)
    parser.add_argument("--spp", type=int)
    parser.add_argument("--integrator")
    parser.add_argument("--tile", type=int, default=64)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--compare", action="store_true")
    parser.add_argument("--output", help="write the frame here (.exr or .png)")
    args = parser.parse_args()

    from distributed import Client, LocalCluster

    scene = glint.load_scene(args.scene)
    settings = dict(spp=args.spp, integrator=args.integrator, threads=1)
    started = time.perf_counter()
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True) as cluster:
        with Client(cluster) as client:
            up = time.perf_counter() - started
            print(f"cluster of {args.workers} worker processes up in {up:.2f} s")
            start = time.perf_counter()
            frame = render_tiles(client, scene, args.width, args.height, tile=args.tile, **settings)
            dask_time = time.perf_counter() - start
    print(f"dask: {args.workers} workers x 1 thread, tiles of {args.tile}: {dask_time:.2f} s")
    if args.compare:
        start = time.perf_counter()
        single = glint.render(
            scene,
            width=args.width,
            height=args.height,
            spp=args.spp,
            integrator=args.integrator,
            threads=args.workers,
        )
        single_time = time.perf_counter() - start
        same = np.array_equal(single.view(np.uint32), frame.view(np.uint32))
        print(f"one process, {args.workers} threads: {single_time:.2f} s; bit-identical: {same}")
    if args.output:
        glint.write_image(args.output, frame)


if __name__ == "__main__":
    main()
