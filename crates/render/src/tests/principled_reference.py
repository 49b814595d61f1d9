"""Prints the table of Mitsuba 3's `principled` and `principledthin` values that
`principled_bsdfs.rs` compares Glint's with (`MITSUBA_VALUES`).

Run with Mitsuba 3.9.1 installed (`pip install mitsuba==3.9.1`):
    python3 crates/render/src/tests/principled_reference.py > /tmp/table.rs
The configurations must be those of `reference_configurations()` in the Rust test, in order.
"""

import math
import random

import mitsuba as mi

mi.set_variant("scalar_rgb")

SCENE_P = {"type": "principled", "base_color": {"type": "rgb", "value": [0.2, 0.8, 0.1]},
           "roughness": 0.15, "specular": 0.7}
SCENE_T = {"type": "principledthin", "base_color": {"type": "rgb", "value": [0.7, 0.1, 0.1]},
           "eta": 1.33}
CONFIGS = [
    dict(SCENE_P, anisotropic=0.05, metallic=0.7, clearcoat=0.9, sheen=0.2),
    dict(SCENE_P, anisotropic=0.8, metallic=0.1, clearcoat=0.1, sheen=0.9),
    {"type": "principled", "base_color": {"type": "rgb", "value": [0.6, 0.4, 0.9]},
     "roughness": 0.4, "anisotropic": 0.5, "metallic": 0.2, "spec_trans": 0.6, "eta": 1.5,
     "spec_tint": 0.5, "sheen": 0.5, "sheen_tint": 0.5, "flatness": 0.5, "clearcoat": 0.5,
     "clearcoat_gloss": 0.5},
    {"type": "principled", "roughness": 0.3, "spec_trans": 0.9, "eta": 0.7},
    {"type": "principled"},
    dict(SCENE_T, anisotropic=0.05, spec_trans=0.2, diff_trans=0.4, sheen=0.1),
    dict(SCENE_T, anisotropic=0.8, spec_trans=0.8, diff_trans=1.4, sheen=0.8),
    {"type": "principledthin", "base_color": {"type": "rgb", "value": [0.3, 0.6, 0.9]},
     "roughness": 0.3, "anisotropic": 0.4, "spec_trans": 0.5, "diff_trans": 0.8, "eta": 1.5,
     "spec_tint": 0.5, "sheen": 0.5, "sheen_tint": 0.5, "flatness": 0.5},
]


def sphere(rng):
    z = rng.uniform(-1.0, 1.0)
    phi = rng.uniform(0.0, 2.0 * math.pi)
    r = math.sqrt(max(0.0, 1.0 - z * z))
    return [r * math.cos(phi), r * math.sin(phi), z]


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def directions(rng):
    """Random pairs, and pairs near the mirror and near straight-through directions, where
    the narrow specular lobes are large."""
    pairs = []
    for _ in range(16):
        pairs.append((sphere(rng), sphere(rng)))
    for _ in range(12):
        wo = sphere(rng)
        jitter = [rng.gauss(0.0, 0.05) for _ in range(3)]
        mirror = [-wo[0] + jitter[0], -wo[1] + jitter[1], wo[2] + jitter[2]]
        through = [-wo[0] + jitter[0], -wo[1] + jitter[1], -wo[2] + jitter[2]]
        pairs.append((wo, normalize(mirror)))
        pairs.append((wo, normalize(through)))
    return pairs


def main():
    rng = random.Random(20240611)
    ctx = mi.BSDFContext()
    print("const MITSUBA_VALUES: &[(usize, [f32; 3], [f32; 3], [f32; 3], f32)] = &[")
    for index, config in enumerate(CONFIGS):
        bsdf = mi.load_dict(config)
        for wo, wi in directions(rng):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(wo)
            value = bsdf.eval(ctx, si, mi.Vector3f(wi))
            pdf = bsdf.pdf(ctx, si, mi.Vector3f(wi))
            f = ", ".join("%.9e" % c for c in value)
            print("    (%d, [%.9e, %.9e, %.9e], [%.9e, %.9e, %.9e], [%s], %.9e)," % (
                index, *wo, *wi, f, pdf))
    print("];")


main()
