#!/usr/bin/env python3
"""Renders the reference for crates/io/tests/path_thinlens.rs: Mitsuba 3's Cornell box (the
triangles of ../shared/refs/cornell/cornell.json, written by ../shared/bench/make_cornell_ref.py)
seen through Mitsuba's `thinlens` sensor focused on the front of the small box, so that the box
is in focus and the back wall, the light and the large box are not.

It renders two halves with different seeds, writes their mean as the reference EXR, and prints
the reference's own noise in the test's relMSE, sigma2_r = relMSE(half1, half2) / 4 (the halves
are independent, each with twice the variance of their mean), which the test takes as a constant.

Usage: make_thinlens_ref.py [--spp 2048] [--size 128] [--variant scalar_rgb]
Needs: pip install mitsuba==3.9.1 numpy (the llvm variants also need libLLVM 19)."""

import argparse
import os
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED_BENCH = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "bench"))
sys.path.insert(0, SHARED_BENCH)
import make_cornell_ref as cornell  # the Cornell box's triangles and materials

# Must match crates/io/tests/path_thinlens.rs.
FOCUS_DISTANCE = 3.3
APERTURE_RADIUS = 0.2


def relative_mse(a, b, reference):
    return float(np.mean((a - b) ** 2 / (reference**2 + 0.01)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=2048)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--out", default=HERE)
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant(args.variant)

    tmp = tempfile.mkdtemp(prefix="thinlens-")

    def mesh(name, tris, bsdf, emitter=None):
        # Through an OBJ file, which every variant loads (scalar ones cannot fill a mi.Mesh
        # from arrays), flat shaded like the course's triangles.
        path = os.path.join(tmp, name + ".obj")
        with open(path, "w") as f:
            f.writelines(
                f"v {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n" for t in tris for p in t
            )
            f.writelines(
                f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}\n" for i in range(len(tris))
            )
        shape = {"type": "obj", "filename": path, "face_normals": True, "bsdf": bsdf}
        if emitter is not None:
            shape["emitter"] = emitter
        return shape

    shapes = {k: (cornell.rect_tris(m), mat) for k, (m, mat) in cornell.RECTS.items()}
    shapes.update(
        {k: (cornell.cube_tris(m), mat) for k, (m, mat) in cornell.CUBES.items()}
    )
    light_tris = cornell.rect_tris(cornell.LIGHT[0])
    bsdfs = {
        k: {"type": "diffuse", "reflectance": {"type": "rgb", "value": c}}
        for k, c in cornell.ALBEDO.items()
    }

    def render(seed, spp):
        scene = {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": -1},
            "sensor": {
                "type": "thinlens",
                "fov": cornell.FOV_DEG,
                "fov_axis": "x",
                "aperture_radius": APERTURE_RADIUS,
                "focus_distance": FOCUS_DISTANCE,
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=cornell.EYE, target=[0, 0, 0], up=[0, 1, 0]
                ),
                "sampler": {"type": "independent", "sample_count": spp},
                "film": {
                    "type": "hdrfilm",
                    "width": args.size,
                    "height": args.size,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
            },
        }
        for name, (tris, mat) in shapes.items():
            scene[name] = mesh(name, tris, bsdfs[mat])
        emitter = {
            "type": "area",
            "radiance": {"type": "rgb", "value": cornell.RADIANCE},
        }
        scene["light"] = mesh("light", light_tris, bsdfs["white"], emitter)
        return np.array(mi.render(mi.load_dict(scene), seed=seed), dtype=np.float64)

    t0 = time.time()
    half = args.spp // 2
    first, second = render(1, half), render(2, half)
    mean = (first + second) / 2
    sigma2_r = relative_mse(first, second, mean) / 4
    base = os.path.join(args.out, f"mitsuba_thinlens_{args.size}_{args.spp}spp")
    mi.util.write_bitmap(base + ".exr", mi.TensorXf(mean.astype(np.float32)))
    print(
        f"{args.variant} {args.size}x{args.size} {args.spp} spp in {time.time() - t0:.0f} s "
        f"-> {base}.exr; reference noise sigma2_r = {sigma2_r:.3e}"
    )


if __name__ == "__main__":
    main()
