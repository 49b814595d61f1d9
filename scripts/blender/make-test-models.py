"""Build Glint's glTF material test models in Blender and export each with Blender's glTF
exporter (GLB) into scenes/gltf/.

Run headless (Blender 3.4, Debian's `blender` package, plus `python3-numpy`, which the
glTF add-on needs for KHR_materials_specular):

    blender -b --factory-startup --python-exit-code 1 \
        -P scripts/blender/make-test-models.py -- scenes/gltf

Every model is built in a fresh, empty Blender file (Z up, metres); the exporter writes it
+Y up. After export the script reads each GLB's JSON back and prints the glTF extensions
the file ended up using, so the README's table can be checked against the files.
"""

import json
import math
import struct
import sys
from pathlib import Path

import bpy

# Reference image size: every model's camera is exported with this aspect ratio (4:3).
WIDTH, HEIGHT = 160, 120


def reset():
    """An empty file: no objects, no materials, no world."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = WIDTH
    scene.render.resolution_y = HEIGHT
    scene.render.resolution_percentage = 100


def material(name, base, metallic=0.0, roughness=0.5, inputs=None):
    """A Principled BSDF material; `inputs` sets further Principled inputs by name."""
    inputs = inputs or {}
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    # Blender's default IOR is 1.45; glTF's is 1.5 (1.45 would export KHR_materials_ior).
    bsdf.inputs["IOR"].default_value = 1.5
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    return mat


def settings_group(mat):
    """The exporter's 'glTF Material Output' node group in `mat` (thickness and the
    original KHR_materials_specular factors live on it), created once per file."""
    from io_scene_gltf2.blender.com.gltf2_blender_material_helpers import (
        create_settings_group,
        get_gltf_node_name,
    )

    name = get_gltf_node_name()
    group = bpy.data.node_groups.get(name) or create_settings_group(name)
    node = mat.node_tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    return node


def assign(obj, mat):
    obj.data.materials.clear()
    obj.data.materials.append(mat)


def sphere(name, location, radius, mat, segments=32, rings=16):
    bpy.ops.mesh.primitive_uv_sphere_add(
        segments=segments, ring_count=rings, radius=radius, location=location
    )
    obj = bpy.context.active_object
    obj.name = name
    bpy.ops.object.shade_smooth()
    assign(obj, mat)
    return obj


def cube(name, location, size, mat, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_cube_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    assign(obj, mat)
    return obj


def plane(name, location, size, mat, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    assign(obj, mat)
    return obj


def camera(location, target, yfov_degrees=40.0):
    """A perspective camera at `location` looking at `target` (Blender coordinates, +Z
    up), vertical field of view `yfov_degrees`."""
    data = bpy.data.cameras.new("Camera")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(yfov_degrees)
    obj = bpy.data.objects.new("Camera", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    direction = (
        target[0] - location[0],
        target[1] - location[1],
        target[2] - location[2],
    )
    from mathutils import Vector

    obj.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj
    return obj


def checker_image(name, size=16, cells=8, dark=(0.1, 0.1, 0.1), light=(0.8, 0.8, 0.8)):
    """A packed checkerboard image (opaque)."""
    image = bpy.data.images.new(name, width=size, height=size, alpha=False)
    pixels = []
    cell = size // cells
    for y in range(size):
        for x in range(size):
            colour = light if ((x // cell) + (y // cell)) % 2 == 0 else dark
            pixels.extend((*colour, 1.0))
    image.pixels = pixels
    image.pack()
    return image


def alpha_image(name, size=32):
    """A packed RGBA image whose alpha varies: the left quarter opaque, then columns of
    alpha 0.8, 0.6, 0.4, 0.2 (cut at 0.5 by MASK), a clear disc in the middle; the colour
    is a red-to-blue ramp over rows."""
    image = bpy.data.images.new(name, width=size, height=size, alpha=True)
    pixels = []
    for y in range(size):
        for x in range(size):
            column = x * 5 // size
            alpha = (1.0, 0.8, 0.6, 0.4, 0.2)[column]
            dx, dy = x + 0.5 - size / 2, y + 0.5 - size / 2
            if dx * dx + dy * dy < (size / 6) ** 2:
                alpha = 0.0
            t = y / (size - 1)
            pixels.extend((0.9 * (1 - t) + 0.05, 0.3, 0.9 * t + 0.05, alpha))
    image.pixels = pixels
    image.alpha_mode = "STRAIGHT"
    image.pack()
    return image


def textured(mat, image, alpha=False):
    """Feed `image` (nearest filtering) into the material's base colour (and alpha)."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Closest"
    links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    if alpha:
        links.new(tex.outputs["Alpha"], bsdf.inputs["Alpha"])
    return tex


# --- the models -------------------------------------------------------------------------


def spheres_metal_rough():
    """Rows metallic 0 (bottom) and 1 (top), columns roughness 0, 0.25, 0.5, 0.75, 1; one
    coloured base; smooth-shaded UV spheres under the sky; the file's camera."""
    base = (0.9, 0.45, 0.15)
    for row, metallic in enumerate((0.0, 1.0)):
        for column, roughness in enumerate((0.0, 0.25, 0.5, 0.75, 1.0)):
            mat = material(
                f"m{metallic:g}_r{roughness:g}",
                base,
                metallic=metallic,
                roughness=roughness,
            )
            sphere(
                f"sphere_m{metallic:g}_r{roughness:g}",
                ((column - 2) * 1.0, 0.0, (row - 0.5) * 1.0),
                0.42,
                mat,
            )
    camera((0.0, -8.0, 0.0), (0.0, 0.0, 0.0), yfov_degrees=28.0)


def metals_only():
    """Five metallic spheres (gold, copper, silver, aluminium, iron) at roughness 0 to 0.8;
    no camera: tests the framing camera."""
    metals = [
        ("gold", (1.0, 0.766, 0.336), 0.0),
        ("copper", (0.955, 0.638, 0.538), 0.2),
        ("silver", (0.972, 0.960, 0.915), 0.4),
        ("aluminium", (0.913, 0.922, 0.924), 0.6),
        ("iron", (0.560, 0.570, 0.580), 0.8),
    ]
    for i, (name, base, roughness) in enumerate(metals):
        mat = material(name, base, metallic=1.0, roughness=roughness)
        sphere(name, ((i - 2) * 1.1, 0.3 * (i % 2), 0.25 * i), 0.5, mat)


def diffuse_only():
    """Lambertian only: metallic 0 and KHR_materials_specular specularFactor 0 (no
    specular lobe at all), so Appendix B reduces to base colour / pi. Flat-shaded cubes,
    a smooth sphere, a floor; the file's camera."""

    def lambert(name, base):
        mat = material(name, base, metallic=0.0, roughness=1.0)
        group = settings_group(mat)
        group.inputs["Specular"].default_value = 0.0
        return mat

    plane("floor", (0.0, 0.0, 0.0), 6.0, lambert("floor", (0.5, 0.5, 0.5)))
    cube(
        "red_cube",
        (-1.2, 0.3, 0.5),
        1.0,
        lambert("red", (0.8, 0.1, 0.08)),
        rotation=(0.0, 0.0, math.radians(25)),
    )
    sphere("green_sphere", (0.3, -0.2, 0.6), 0.6, lambert("green", (0.1, 0.7, 0.15)))
    cube(
        "blue_box",
        (1.4, 0.8, 0.4),
        0.8,
        lambert("blue", (0.1, 0.2, 0.85)),
        rotation=(0.0, 0.0, math.radians(-15)),
    )
    camera((4.0, -5.0, 3.5), (0.0, 0.0, 0.4), yfov_degrees=40.0)


def emissive():
    """An emissive panel (emissiveFactor (1, 0.85, 0.6), KHR_materials_emissive_strength 8)
    lighting a diffuse sphere and floor; the sky lights them too."""
    emitter = material(
        "panel",
        (0.0, 0.0, 0.0),
        roughness=1.0,
        inputs={"Emission": (1.0, 0.85, 0.6, 1.0), "Emission Strength": 8.0},
    )
    plane("panel", (0.0, 1.2, 1.2), 1.5, emitter, rotation=(math.radians(90), 0.0, 0.0))
    plane(
        "floor", (0.0, 0.0, 0.0), 5.0, material("floor", (0.6, 0.6, 0.6), roughness=0.9)
    )
    sphere(
        "sphere",
        (0.0, 0.0, 0.5),
        0.5,
        material("white", (0.8, 0.8, 0.8), roughness=0.7),
    )
    camera((3.0, -4.0, 2.5), (0.0, 0.4, 0.6), yfov_degrees=40.0)


def transmission():
    """A glass sphere (transmission 1, ior 1.5, KHR_materials_volume thickness 1 with a
    blue-green attenuation) and a thin transmissive sheet (transmission 0.9, no volume)
    in front of a checker wall and floor."""
    checker = checker_image("checker")
    floor = material("checker", (1.0, 1.0, 1.0), roughness=0.8)
    textured(floor, checker)
    plane("floor", (0.0, 0.5, 0.0), 5.0, floor)
    plane("wall", (0.0, 3.0, 2.5), 5.0, floor, rotation=(math.radians(90), 0.0, 0.0))

    glass = material(
        "glass",
        (1.0, 1.0, 1.0),
        roughness=0.0,
        inputs={"Transmission": 1.0, "IOR": 1.5},
    )
    group = settings_group(glass)
    group.inputs["Thickness"].default_value = 1.0
    absorption = glass.node_tree.nodes.new("ShaderNodeVolumeAbsorption")
    absorption.inputs["Color"].default_value = (0.6, 0.9, 0.8, 1.0)
    absorption.inputs["Density"].default_value = 0.5
    output = glass.node_tree.nodes["Material Output"]
    glass.node_tree.links.new(absorption.outputs[0], output.inputs["Volume"])
    sphere("glass_sphere", (-0.8, 0.0, 0.6), 0.6, glass, segments=48, rings=24)

    sheet = material(
        "sheet",
        (0.9, 0.95, 1.0),
        roughness=0.1,
        inputs={"Transmission": 0.9, "IOR": 1.5},
    )
    plane(
        "sheet",
        (1.0, -0.2, 0.7),
        1.2,
        sheet,
        rotation=(math.radians(90), 0.0, math.radians(-20)),
    )
    camera((1.0, -5.0, 2.0), (0.0, 0.5, 0.6), yfov_degrees=40.0)


def alpha_modes():
    """Three quads with the same RGBA texture (nearest filtering): OPAQUE, MASK (cutoff
    0.5) and BLEND, in front of a green wall."""
    image = alpha_image("alpha")
    modes = [("opaque", "OPAQUE"), ("mask", "CLIP"), ("blend", "BLEND")]
    for i, (name, method) in enumerate(modes):
        mat = material(name, (1.0, 1.0, 1.0), roughness=1.0)
        textured(mat, image, alpha=method != "OPAQUE")
        mat.blend_method = method
        if method == "CLIP":
            mat.alpha_threshold = 0.5
        plane(
            name,
            ((i - 1) * 1.1, 0.0, 0.0),
            1.0,
            mat,
            rotation=(math.radians(90), 0.0, 0.0),
        )
    plane(
        "wall",
        (0.0, 1.0, 0.0),
        6.0,
        material("wall", (0.1, 0.6, 0.2), roughness=1.0),
        rotation=(math.radians(90), 0.0, 0.0),
    )
    camera((0.0, -4.5, 0.0), (0.0, 0.0, 0.0), yfov_degrees=30.0)


def punctual_lights():
    """A point, a spot and a sun light (KHR_lights_punctual) over a floor with a sphere and
    a cube; dielectric materials."""
    plane(
        "floor", (0.0, 0.0, 0.0), 8.0, material("floor", (0.7, 0.7, 0.7), roughness=0.9)
    )
    sphere(
        "sphere",
        (-0.8, 0.0, 0.5),
        0.5,
        material("orange", (0.9, 0.4, 0.1), roughness=0.5),
    )
    cube(
        "cube",
        (0.9, 0.3, 0.4),
        0.8,
        material("grey", (0.5, 0.5, 0.55), roughness=0.3),
        rotation=(0.0, 0.0, math.radians(30)),
    )

    point = bpy.data.lights.new("point", "POINT")
    point.energy = 200.0  # W; exported as 200 / (4 pi) * 683 cd
    point.color = (1.0, 0.9, 0.8)
    point.shadow_soft_size = 0.0
    obj = bpy.data.objects.new("point", point)
    obj.location = (-1.5, -1.0, 2.0)
    bpy.context.scene.collection.objects.link(obj)

    spot = bpy.data.lights.new("spot", "SPOT")
    spot.energy = 400.0
    spot.color = (0.7, 0.8, 1.0)
    spot.spot_size = math.radians(50)
    spot.spot_blend = 0.2
    spot.shadow_soft_size = 0.0
    obj = bpy.data.objects.new("spot", spot)
    obj.location = (2.0, -1.0, 3.0)
    obj.rotation_euler = (math.radians(30), math.radians(20), 0.0)
    bpy.context.scene.collection.objects.link(obj)

    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = 1.5  # W/m^2; exported as 1.5 * 683 lx
    sun.angle = 0.0
    obj = bpy.data.objects.new("sun", sun)
    obj.rotation_euler = (math.radians(40), 0.0, math.radians(-30))
    bpy.context.scene.collection.objects.link(obj)
    camera((3.5, -5.0, 3.0), (0.0, 0.0, 0.4), yfov_degrees=40.0)


def clearcoat_specular():
    """Clearcoat (KHR_materials_clearcoat) and dielectric specular strength
    (KHR_materials_specular) on four spheres: clearcoat 1 at clearcoat roughness 0.05 and
    0.4 over a rough red base, Principled specular 0.25 and 1.0 (F0 0.02 and 0.08)."""
    red = (0.7, 0.05, 0.05)
    specs = [
        ("coat_smooth", red, {"Clearcoat": 1.0, "Clearcoat Roughness": 0.05}),
        ("coat_rough", red, {"Clearcoat": 1.0, "Clearcoat Roughness": 0.4}),
        ("specular_low", (0.1, 0.3, 0.7), {"Specular": 0.25}),
        ("specular_high", (0.1, 0.3, 0.7), {"Specular": 1.0}),
    ]
    for i, (name, base, inputs) in enumerate(specs):
        mat = material(name, base, roughness=0.6 if i < 2 else 0.3, inputs=inputs)
        sphere(name, ((i - 1.5) * 1.1, 0.0, 0.0), 0.5, mat)
    camera((0.0, -7.0, 1.5), (0.0, 0.0, 0.0), yfov_degrees=30.0)


MODELS = {
    "spheres_metal_rough": spheres_metal_rough,
    "metals_only": metals_only,
    "diffuse_only": diffuse_only,
    "emissive": emissive,
    "transmission": transmission,
    "alpha_modes": alpha_modes,
    "punctual_lights": punctual_lights,
    "clearcoat_specular": clearcoat_specular,
}


def glb_json(path):
    """The JSON chunk of a GLB file."""
    data = Path(path).read_bytes()
    magic, _version, _length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67, f"{path}: not a GLB"
    chunk_length, chunk_type = struct.unpack_from("<II", data, 12)
    assert chunk_type == 0x4E4F534A, f"{path}: first chunk is not JSON"
    return json.loads(data[20 : 20 + chunk_length])


def export(path, original_specular):
    bpy.ops.export_scene.gltf(
        filepath=str(path),
        export_format="GLB",
        export_cameras=True,
        export_lights=True,
        convert_lighting_mode="SPEC",
        export_yup=True,
        export_apply=True,
        # Texture coordinates only where a texture reads them (smaller files).
        export_texcoords=bool(bpy.data.images),
        export_normals=True,
        export_tangents=False,
        export_colors=False,
        export_materials="EXPORT",
        # KHR_materials_specular from the 'glTF Material Output' group's factors (the only
        # way 3.4 writes specularFactor) where a model sets them; else from Principled.
        export_original_specular=original_specular,
        export_animations=False,
        export_extras=False,
    )


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    out = Path(argv[0] if argv else "scenes/gltf")
    only = set(argv[1:])
    out.mkdir(parents=True, exist_ok=True)
    for name, build in MODELS.items():
        if only and name not in only:
            continue
        reset()
        build()
        path = out / f"{name}.glb"
        export(path, original_specular=name == "diffuse_only")
        doc = glb_json(path)
        used = doc.get("extensionsUsed", [])
        print(
            f"MODEL {name}: {path.stat().st_size} bytes, extensions {used or 'none'}, "
            f"cameras {len(doc.get('cameras', []))}, "
            f"materials {[m.get('name') for m in doc.get('materials', [])]}"
        )


main()
