"""Which Cycles node graph is closest to glTF Appendix B? Measured in a white furnace.

A sphere alone under a uniform white sky of radiance 1 reflects, at a point whose normal
makes cos(theta) = mu with the view direction, exactly its BRDF's directional albedo
E(mu) = integral of f cos(theta_i) (it is convex: every reflected ray sees the sky). Each
graph is rendered with an orthographic camera (so mu follows from the pixel's position on
the disc) and compared with E(mu) of Appendix B (Lambert diffuse times 1 - F(V.H),
GGX with height-correlated Smith, Schlick Fresnel), integrated numerically here.

    blender -b --factory-startup --python-exit-code 1 \
        -P scripts/blender/measure-graphs.py -- [--spp N]

Prints a table of the mean and the worst |relative difference| over the disc (pixels within
0.9 of the radius), per graph, metallic and roughness; scripts/gltf-references.sh does
not run it (the figures are quoted in crates/io/tests/gltf_refs/README.md).
"""

import importlib.util
import math
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np

HERE = Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location("refs", HERE / "render-references.py")
refs = importlib.util.module_from_spec(spec)
spec.loader.exec_module(refs)  # main() runs only as __main__

SIZE = 96
BASE = (0.9, 0.45, 0.15)
ROUGHNESS = (0.0, 0.25, 0.5, 1.0)


def schlick(f0, vh):
    return f0 + (1 - f0) * (1 - vh) ** 5


def appendix_b_albedo(mu, roughness, metallic, base, n=384):
    """E(mu) per channel of Appendix B's BRDF (metallic 0 or 1), by stratified sampling of
    the half vector from D(h) cos(theta_h)."""
    base = np.asarray(base, dtype=np.float64)
    v = np.array([math.sqrt(max(0.0, 1 - mu * mu)), 0.0, mu])
    if roughness == 0.0:
        spec = schlick(base, mu) if metallic else schlick(0.04, mu) * np.ones(3)
        if metallic:
            return spec
        diffuse = base * (1 - 0.04 - 0.96 * np.polyval(refs.K_FIT, mu))
        return diffuse + spec
    a = roughness * roughness
    u1 = (np.arange(n) + 0.5) / n
    u2 = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(u1, u2, indexing="ij")
    theta = np.arctan(a * np.sqrt(u1 / (1 - u1)))
    phi = 2 * math.pi * u2
    h = np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1
    )
    vh = h @ v
    l_dir = 2 * vh[..., None] * h - v
    nl, nh, nv = l_dir[..., 2], h[..., 2], mu
    ok = (nl > 0) & (vh > 0)
    nl_c = np.clip(nl, 1e-9, 1)
    vis = 0.5 / (
        nl_c * np.sqrt(nv * nv * (1 - a * a) + a * a)
        + nv * np.sqrt(nl_c * nl_c * (1 - a * a) + a * a)
    )
    weight = np.where(ok, vis * nl_c * 4 * vh / nh, 0.0)
    if metallic:
        f = schlick(base[None, None, :], np.clip(vh, 0, 1)[..., None])
        return (weight[..., None] * f).mean(axis=(0, 1))
    f = schlick(0.04, np.clip(vh, 0, 1))
    spec = (weight * f).mean()
    diffuse = base * (1 - 0.04 - 0.96 * np.polyval(refs.K_FIT, mu))
    return diffuse + spec


def build(graph, metallic, roughness):
    refs.reset()
    scene = bpy.context.scene
    refs.cycles_common(scene)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0)
    bpy.ops.object.shade_smooth()
    obj = bpy.context.active_object
    mat = bpy.data.materials.new("m")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    default_distribution = bsdf.distribution
    bsdf.inputs["Base Color"].default_value = (*BASE, 1)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["IOR"].default_value = 1.5
    obj.data.materials.append(mat)
    if graph == "principled-ggx":
        bsdf.distribution = "GGX"
    elif graph == "principled-multi":
        bsdf.distribution = "MULTI_GGX"
    elif graph.startswith("appendix-b"):
        refs.LOBES = (
            "principled" if graph == "appendix-b-principled-lobes" else "schlick"
        )
        refs.appendix_b_graph(mat, {})
    cam = bpy.data.cameras.new("c")
    cam.type = "ORTHO"
    cam.ortho_scale = 2.2
    cam_obj = bpy.data.objects.new("c", cam)
    scene.collection.objects.link(cam_obj)
    cam_obj.location = (0, -5, 0)
    cam_obj.rotation_euler = (math.pi / 2, 0, 0)
    scene.camera = cam_obj
    scene.render.resolution_x = SIZE
    scene.render.resolution_y = SIZE
    world = bpy.data.worlds.new("w")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.world = world
    c = scene.cycles
    c.pixel_filter_type = "BOX"
    c.filter_width = 0.01  # pixel centres: mu is exact per pixel
    c.max_bounces = 64
    c.glossy_bounces = 64
    c.diffuse_bounces = 64
    return scene, default_distribution


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    spp = int(argv[argv.index("--spp") + 1]) if "--spp" in argv else 512
    only = argv[argv.index("--graphs") + 1].split(",") if "--graphs" in argv else None
    coords = (np.arange(SIZE) + 0.5) / SIZE * 2.2 - 1.1
    x, y = np.meshgrid(coords, -coords)
    r2 = x * x + y * y
    inside = r2 < 0.9**2
    mu = np.sqrt(np.clip(1 - r2, 0, 1))
    table = {}
    graphs = [
        "principled-importer",
        "principled-ggx",
        "principled-multi",
        "appendix-b-principled-lobes",
        "appendix-b",
    ]
    graphs = [g for g in graphs if only is None or g in only]
    for metallic in (0.0, 1.0):
        for roughness in ROUGHNESS:
            mus = np.linspace(0, 1, 41)
            curve = np.array(
                [appendix_b_albedo(m, roughness, metallic, BASE) for m in mus]
            )
            truth = np.stack([np.interp(mu, mus, curve[:, c]) for c in range(3)], -1)
            for graph in graphs:
                scene, default = build(graph, metallic, roughness)
                scene.cycles.samples = spp
                with tempfile.TemporaryDirectory() as tmp:
                    data = refs.render_to(scene, Path(tmp) / "m.exr")
                image = np.stack(
                    [refs.channel(data, f"Combined.{ch}") for ch in "RGB"], -1
                )
                rel = np.abs(image[inside] - truth[inside]) / truth[inside]
                signed = ((image[inside] - truth[inside]) / truth[inside]).mean()
                table[(graph, metallic, roughness)] = (rel.mean(), rel.max(), signed)
                print(
                    f"MEASURE {graph:26s} metallic {metallic:g} roughness {roughness:4g}: "
                    f"mean |rel| {rel.mean():.4f}, max {rel.max():.4f}, mean signed {signed:+.4f}"
                    f" (importer's default distribution {default})"
                )
    print("| graph | metallic | " + " | ".join(f"r {r:g}" for r in ROUGHNESS) + " |")
    for graph in graphs:
        for metallic in (0.0, 1.0):
            cells = [table.get((graph, metallic, r)) for r in ROUGHNESS]
            if not all(cells):
                continue
            text = " | ".join(f"{m * 100:.1f}% ({s * 100:+.1f}%)" for m, _, s in cells)
            print(f"| {graph} | {metallic:g} | {text} |")


main()
