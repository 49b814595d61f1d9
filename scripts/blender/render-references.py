"""Render Blender/Cycles references for Glint's glTF importer.

For every shared model (../shared/gltf) and every model in scenes/gltf/, import it with
Blender's glTF importer, set the camera (the file's first in depth-first node order, or
Glint's framing camera), the world (a white sky of radiance 1 when the file brings no
light: no punctual light and no emissive material) and render with Cycles:

- layers (1 sample at the pixel centre: box filter 0.01 px wide): depth (distance along
  the ray, Camera Data 'View Distance'), normal (Geometry 'True Normal': the geometric
  normal, which Cycles turns towards the ray, converted to glTF axes) and albedo (what
  feeds the importer's Principled 'Base Color': factor x texture x vertex colour, clamped
  to [0, 1]; 1 where the ray escapes to the white sky, as Glint's layer), through AOVs;
- beauty (two independent halves of N/2 samples, box filter 1 px, no denoising, no
  clamping) with the node graph closest to glTF Appendix B that Blender allows (README).

Writes crates/io/tests/gltf_refs/<model>.exr (channels R G B = beauty, albedo.R/G/B,
normal.X/Y/Z, depth.Z, and `mask` where some pixels' layers are not comparable) and
manifest.json. Run through scripts/gltf-references.sh, or:

    blender -b --factory-startup --python-exit-code 1 \
        -P scripts/blender/render-references.py -- [--spp N] [--only NAME ...]
"""

import importlib.util
import json
import math
import shutil
import struct
import sys
import tempfile
import time
from pathlib import Path

import bpy
import numpy as np
from mathutils import Matrix, Vector

# Debian's Blender 3.4 glTF importer still uses numpy.bool, which numpy 1.24 (Debian 12's
# python3-numpy) removed: restore the alias (it was the builtin bool).
if "bool" not in np.__dict__:
    np.bool = bool


def load_module(name, path):
    """A helper module beside this script (no sys.path changes, no late imports)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


exr_io = load_module("exr_io", Path(__file__).resolve().parent / "exr_io.py")

REPO = Path(__file__).resolve().parents[2]
SHARED = REPO / ".." / "shared" / "gltf"
OUT = REPO / "crates" / "io" / "tests" / "gltf_refs"
WIDTH, HEIGHT = 160, 120
FRAMING_FOV = 40.0
GLTF_IOR = 1.5

# (name, path relative to the repository root). The shared models are reached as
# ../shared/gltf/, as the tests reach them.
SHARED_MODELS = [
    ("Box", "Box/Box.gltf"),
    ("TriangleWithoutIndices", "TriangleWithoutIndices/TriangleWithoutIndices.gltf"),
    ("SimpleMeshes", "SimpleMeshes/SimpleMeshes.gltf"),
    ("BoxVertexColors", "BoxVertexColors/BoxVertexColors.gltf"),
    ("MultipleScenes", "MultipleScenes/MultipleScenes.gltf"),
    ("SimpleSparseAccessor", "SimpleSparseAccessor/SimpleSparseAccessor.gltf"),
    ("BoxTextured", "BoxTextured-Embedded/BoxTextured.gltf"),
    ("BoxTextured-GLB", "BoxTextured-GLB/BoxTextured.glb"),
    ("TextureCoordinateTest", "TextureCoordinateTest/TextureCoordinateTest.gltf"),
    ("gltf-rs-Box", "gltf-rs/Box.gltf"),
    ("gltf-rs-Box-GLB", "gltf-rs/Box.glb"),
    ("gltf-rs-box_sparse", "gltf-rs/box_sparse.gltf"),
    ("gltf-rs-box_sparse-GLB", "gltf-rs/box_sparse.glb"),
    ("gltf-rs-minimal_accessor_min_max", "gltf-rs/minimal_accessor_min_max.gltf"),
]


def models():
    found = [(name, "../shared/gltf/" + path) for name, path in SHARED_MODELS]
    for path in sorted((REPO / "scenes" / "gltf").glob("*.glb")):
        found.append((path.stem, str(path.relative_to(REPO))))
    return found


# --- glTF coordinates ----------------------------------------------------------------
# Blender's importer maps glTF (x, y, z) (+Y up) to Blender (x, -z, y) (+Z up); the script
# checks it on every file with a camera (the imported camera against the file's).
TO_BLENDER = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
TO_GLTF = TO_BLENDER.inverted()


def to_gltf(v):
    return (v[0], v[2], -v[1])


# --- reading the file's JSON ---------------------------------------------------------


def read_document(path):
    data = Path(path).read_bytes()
    if data[:4] == b"glTF":
        length, kind = struct.unpack_from("<II", data, 12)
        assert kind == 0x4E4F534A
        return json.loads(data[20 : 20 + length]), data
    return json.loads(data), data


def node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]  # column-major
        return Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])
    t = Matrix.Translation(node.get("translation", [0, 0, 0]))
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    from mathutils import Quaternion

    r = Quaternion((w, x, y, z)).to_matrix().to_4x4()
    s = Matrix.Diagonal((*node.get("scale", [1, 1, 1]), 1.0))
    return t @ r @ s


def scene_nodes(doc):
    """(node index, world matrix in glTF coordinates) in depth-first order of the default
    scene (scene 0 when `scene` is absent, as Glint does)."""
    scenes = doc.get("scenes", [])
    if not scenes:
        roots = [
            i
            for i in range(len(doc.get("nodes", [])))
            if not any(i in n.get("children", []) for n in doc["nodes"])
        ]
    else:
        roots = scenes[doc.get("scene", 0)].get("nodes", [])
    order = []

    def walk(i, parent):
        world = parent @ node_matrix(doc["nodes"][i])
        order.append((i, world))
        for child in doc["nodes"][i].get("children", []):
            walk(child, world)

    for root in roots:
        walk(root, Matrix.Identity(4))
    return order


def renamed_copy(path, doc, raw, directory):
    """A copy of the model whose nodes are named N<index> and materials M<index> (so that
    the imported objects and materials can be told apart), with its external files beside
    it."""
    doc = json.loads(json.dumps(doc))
    for i, node in enumerate(doc.get("nodes", [])):
        node["name"] = f"N{i}"
    for i, material in enumerate(doc.get("materials", [])):
        material["name"] = f"M{i}"
    source = Path(path)
    for item in doc.get("buffers", []) + doc.get("images", []):
        uri = item.get("uri")
        if uri and not uri.startswith("data:"):
            shutil.copy(source.parent / uri, directory / uri)
    if raw[:4] == b"glTF":
        length, _ = struct.unpack_from("<II", raw, 12)
        text = json.dumps(doc).encode()
        text += b" " * ((4 - len(text) % 4) % 4)
        rest = raw[20 + length :]
        body = struct.pack("<II", len(text), 0x4E4F534A) + text + rest
        out = directory / "model.glb"
        out.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    else:
        out = directory / "model.gltf"
        out.write_text(json.dumps(doc))
    return out


# --- Appendix B helpers --------------------------------------------------------------


def schlick_weight_fit(degree=6):
    """k(mu) = (1/pi) * integral over the hemisphere of (1 - V.H)^5 cos(theta_i) dw_i for
    a view direction at cos(theta_v) = mu: the diffuse lobe of Appendix B is weighted by
    1 - F(V.H), whose directional average is 1 - F0 - (1 - F0) k(mu). Returns polynomial
    coefficients in mu (numpy.polyval order) and the fit's worst error."""
    n = 256
    theta = (np.arange(n) + 0.5) / n * (math.pi / 2)
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * (2 * math.pi)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    li = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    dw = (math.pi / 2 / n) * (2 * math.pi / (2 * n)) * np.sin(th)
    mus = np.linspace(0.0, 1.0, 65)
    ks = []
    for mu in mus:
        v = np.array([math.sqrt(max(0.0, 1 - mu * mu)), 0.0, mu])
        h = li + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        vh = np.clip(h @ v, 0.0, 1.0)
        ks.append(np.sum((1 - vh) ** 5 * np.cos(th) * dw) / math.pi)
    ks = np.array(ks)
    coefficients = np.polyfit(mus, ks, degree)
    error = np.abs(np.polyval(coefficients, mus) - ks).max()
    return coefficients, error


K_FIT, K_FIT_ERROR = schlick_weight_fit()
# The beauty's specular lobes: "schlick" (Glossy BSDF x Schlick's Fresnel at N.V) or
# "principled" (the Principled BSDF's own); measure-graphs.py compares both.
LOBES = "schlick"


# --- scene set-up --------------------------------------------------------------------


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.render.resolution_x = WIDTH
    scene.render.resolution_y = HEIGHT
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    return scene


def socket_source(tree, socket):
    """The output socket linked into `socket`, or None."""
    for link in tree.links:
        if link.to_socket == socket:
            return link.from_socket
    return None


def feed(tree, source, socket, default):
    """Link `source` into `socket`, or set `default` when there is no source."""
    if source is not None:
        tree.links.new(source, socket)
    elif default is not None:
        socket.default_value = default


def default_material(vertex_color):
    """glTF's default material (base colour 1, metallic 1, roughness 1), times COLOR_0
    where the primitive has it (the spec's rule; Blender leaves such primitives without a
    material)."""
    mat = bpy.data.materials.new("glTF default" + (" vc" if vertex_color else ""))
    mat.use_nodes = True
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (1, 1, 1, 1)
    bsdf.inputs["Metallic"].default_value = 1.0
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["IOR"].default_value = GLTF_IOR
    if vertex_color:
        attribute = tree.nodes.new("ShaderNodeVertexColor")
        attribute.layer_name = vertex_color
        tree.links.new(attribute.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def principled(mat):
    if not mat or not mat.use_nodes:
        return None
    for node in mat.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            return node
    return None


def output_node(tree):
    for node in tree.nodes:
        if node.type == "OUTPUT_MATERIAL" and node.is_active_output:
            return node
    return tree.nodes.new("ShaderNodeOutputMaterial")


def math_node(tree, operation, a, b=None):
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    for i, value in enumerate((a, b)):
        if value is None:
            continue
        if isinstance(value, (int, float)):
            node.inputs[i].default_value = value
        else:
            tree.links.new(value, node.inputs[i])
    return node.outputs[0]


def material_info(doc, mat):
    """The glTF material a Blender material was made from (named M<index> by
    `renamed_copy`), or {} for the script's own default material."""
    name = mat.name.split(".")[0]
    if name.startswith("M") and name[1:].isdigit():
        return doc["materials"][int(name[1:])]
    return {}


def alpha_fix(tree, bsdf, gltf_material):
    """Which hits are absent, made explicit in the node tree: Cycles reads Principled
    'Alpha' as stochastic coverage, ignores Blender's 'Alpha Clip' blend mode (all the
    importer sets for MASK) and never culls back faces. Here MASK is cut at alphaCutoff
    (opaque where alpha >= cutoff) and a single-sided material (doubleSided false, not a
    volume's boundary) is transparent where it is seen from behind: Glint's rules. Returns
    the 0/1 coverage the AOVs are multiplied by (None when every hit counts)."""
    mode = gltf_material.get("alphaMode", "OPAQUE")
    alpha = bsdf.inputs["Alpha"]
    source = socket_source(tree, alpha)
    keep = None
    if mode == "MASK":
        cutoff = gltf_material.get("alphaCutoff", 0.5)
        below = math_node(tree, "LESS_THAN", source or alpha.default_value, cutoff)
        keep = math_node(tree, "SUBTRACT", 1.0, below)
    volume = gltf_material.get("extensions", {}).get("KHR_materials_volume", {})
    if not gltf_material.get("doubleSided", False) and not volume.get(
        "thicknessFactor"
    ):
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        front = math_node(tree, "SUBTRACT", 1.0, geometry.outputs["Backfacing"])
        keep = front if keep is None else math_node(tree, "MULTIPLY", keep, front)
    if keep is not None:
        coverage = keep
        if mode == "BLEND":
            coverage = math_node(tree, "MULTIPLY", source or alpha.default_value, keep)
        tree.links.new(coverage, alpha)
    return keep


def add_aovs(scene, mat, doc):
    """Albedo, normal and depth AOVs for the layers' render; `excluded` marks BLEND."""
    tree = mat.node_tree
    bsdf = principled(mat)
    info = material_info(doc, mat)
    alpha = alpha_fix(tree, bsdf, info) if bsdf else None
    geometry = tree.nodes.new("ShaderNodeNewGeometry")
    cam = tree.nodes.new("ShaderNodeCameraData")

    def aov(name, source, default=None, is_color=True):
        node = tree.nodes.new("ShaderNodeOutputAOV")
        # Blender 3.x: the node's name is the AOV it writes (aov_name from 4.0 on).
        node.name = name
        socket = node.inputs["Color" if is_color else "Value"]
        if alpha is not None:
            # A cut-away hit must add nothing: AOVs add up over the camera path's
            # transparent hits, and the surface behind adds its own value.
            if is_color:
                mix = tree.nodes.new("ShaderNodeMix")
                mix.data_type = "RGBA"
                mix.blend_type = "MIX"
                tree.links.new(alpha, mix.inputs["Factor"])
                mix.inputs[6].default_value = (0, 0, 0, 1)
                feed(tree, source, mix.inputs[7], default)
                tree.links.new(mix.outputs[2], socket)
            else:
                tree.links.new(math_node(tree, "MULTIPLY", source, alpha), socket)
        else:
            feed(tree, source, socket, default)

    base = bsdf.inputs["Base Color"] if bsdf else None
    base_source = socket_source(tree, base) if base else None
    aov("albedo", base_source, tuple(base.default_value) if base else (1, 1, 1, 1))
    aov("normal", geometry.outputs["True Normal"])
    aov("depth", cam.outputs["View Distance"], is_color=False)
    blend = 1.0 if info.get("alphaMode") == "BLEND" else 0.0
    node = tree.nodes.new("ShaderNodeOutputAOV")
    node.name = "excluded"
    node.inputs["Value"].default_value = blend


def appendix_b_graph(mat, doc):
    """Rebuild the surface of an imported material as close to glTF Appendix B as Cycles
    nodes allow (README, 'Beauty'): returns a note for the manifest."""
    tree = mat.node_tree
    bsdf = principled(mat)
    if bsdf is None:
        return "no Principled BSDF: left as imported"
    info = material_info(doc, mat)
    bsdf.distribution = "GGX"
    bsdf.subsurface_method = "BURLEY"
    alpha_fix(tree, bsdf, info)
    ext = info.get("extensions", {})
    inputs = bsdf.inputs
    complex_lobes = (
        inputs["Transmission"].default_value > 0
        or socket_source(tree, inputs["Transmission"]) is not None
        or inputs["Clearcoat"].default_value > 0
        or socket_source(tree, inputs["Clearcoat"]) is not None
    )
    if complex_lobes:
        return "transmission/clearcoat: importer's Principled BSDF (single-scatter GGX)"

    out = output_node(tree)
    nodes, links = tree.nodes, tree.links
    base_src = socket_source(tree, inputs["Base Color"])
    base_val = tuple(inputs["Base Color"].default_value)
    metal_src = socket_source(tree, inputs["Metallic"])
    metal_val = inputs["Metallic"].default_value
    rough_src = socket_source(tree, inputs["Roughness"])
    rough_val = inputs["Roughness"].default_value
    normal_src = socket_source(tree, inputs["Normal"])

    ior = ext.get("KHR_materials_ior", {}).get("ior", GLTF_IOR)
    spec = ext.get("KHR_materials_specular", {})
    s = spec.get("specularFactor", 1.0)
    colour = spec.get("specularColorFactor", [1.0, 1.0, 1.0])
    f0 = min(((ior - 1) / (ior + 1)) ** 2 * (sum(colour) / 3.0), 1.0)

    # Dielectric: Lambert (Diffuse BSDF, roughness 0) weighted by the directional average
    # of 1 - F(V.H), plus the Principled BSDF's specular lobe alone (black base).
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    feed(tree, base_src, diffuse.inputs["Color"], base_val)
    feed(tree, normal_src, diffuse.inputs["Normal"], None)
    weight = nodes.new("ShaderNodeLayerWeight")
    weight.inputs["Blend"].default_value = 0.5
    feed(tree, normal_src, weight.inputs["Normal"], None)
    mu = math_node(tree, "SUBTRACT", 1.0, weight.outputs["Facing"])
    k = None
    for c in K_FIT:  # Horner: k = (...(c0 mu + c1) mu + ...) + cn
        k = math_node(tree, "MULTIPLY_ADD", k if k is not None else 0.0, mu)
        k.node.inputs[2].default_value = float(c)
    k_val = math_node(tree, "MAXIMUM", k, 0.0)
    fresnel = math_node(tree, "MULTIPLY_ADD", k_val, 1.0 - f0)
    fresnel.node.inputs[2].default_value = f0
    w = math_node(tree, "SUBTRACT", 1.0, math_node(tree, "MULTIPLY", fresnel, s))
    diffuse_part = nodes.new("ShaderNodeMixShader")
    links.new(w, diffuse_part.inputs["Fac"])
    links.new(diffuse.outputs[0], diffuse_part.inputs[2])

    if LOBES == "schlick":
        # Glossy BSDF (GGX, single scattering, no Fresnel of its own) weighted by Schlick's
        # Fresnel at N.V: exact at roughness 0 (there V.H = N.V); README, 'Beauty'.
        one_minus = weight.outputs["Facing"]
        p5 = math_node(tree, "POWER", one_minus, 5.0)
        f_dielectric = math_node(tree, "MULTIPLY_ADD", p5, 1.0 - f0)
        f_dielectric.node.inputs[2].default_value = f0
        specular = nodes.new("ShaderNodeBsdfGlossy")
        specular.distribution = "GGX"
        specular.inputs["Color"].default_value = (1, 1, 1, 1)
        feed(tree, rough_src, specular.inputs["Roughness"], rough_val)
        feed(tree, normal_src, specular.inputs["Normal"], None)
        specular_part = nodes.new("ShaderNodeMixShader")
        links.new(
            math_node(tree, "MULTIPLY", f_dielectric, s), specular_part.inputs["Fac"]
        )
        links.new(specular.outputs[0], specular_part.inputs[2])
        metal = nodes.new("ShaderNodeBsdfGlossy")
        metal.distribution = "GGX"
        feed(tree, rough_src, metal.inputs["Roughness"], rough_val)
        feed(tree, normal_src, metal.inputs["Normal"], None)
        f_metal = nodes.new("ShaderNodeMix")
        f_metal.data_type = "RGBA"
        f_metal.blend_type = "MIX"
        links.new(p5, f_metal.inputs["Factor"])
        feed(tree, base_src, f_metal.inputs[6], base_val)
        f_metal.inputs[7].default_value = (1, 1, 1, 1)
        links.new(f_metal.outputs[2], metal.inputs["Color"])
    else:
        # The Principled BSDF's own lobes: its specular alone (black base), and at
        # metallic 1 (F0 = base colour); Fresnel on V.H, a normalised dielectric curve.
        specular = nodes.new("ShaderNodeBsdfPrincipled")
        specular.distribution = "GGX"
        specular.inputs["Base Color"].default_value = (0, 0, 0, 1)
        specular.inputs["Metallic"].default_value = 0.0
        specular.inputs["Specular"].default_value = f0 / 0.08
        specular.inputs["Specular Tint"].default_value = 0.0
        specular.inputs["Sheen"].default_value = 0.0
        feed(tree, rough_src, specular.inputs["Roughness"], rough_val)
        feed(tree, normal_src, specular.inputs["Normal"], None)
        specular_part = nodes.new("ShaderNodeMixShader")
        specular_part.inputs["Fac"].default_value = s
        links.new(specular.outputs[0], specular_part.inputs[2])
        metal = nodes.new("ShaderNodeBsdfPrincipled")
        metal.distribution = "GGX"
        feed(tree, base_src, metal.inputs["Base Color"], base_val)
        metal.inputs["Metallic"].default_value = 1.0
        metal.inputs["Specular Tint"].default_value = 0.0
        metal.inputs["Sheen"].default_value = 0.0
        feed(tree, rough_src, metal.inputs["Roughness"], rough_val)
        feed(tree, normal_src, metal.inputs["Normal"], None)
    dielectric = nodes.new("ShaderNodeAddShader")
    links.new(diffuse_part.outputs[0], dielectric.inputs[0])
    links.new(specular_part.outputs[0], dielectric.inputs[1])

    surface = nodes.new("ShaderNodeMixShader")
    feed(tree, metal_src, surface.inputs["Fac"], metal_val)
    links.new(dielectric.outputs[0], surface.inputs[1])
    links.new(metal.outputs[0], surface.inputs[2])
    result = surface.outputs[0]

    emission_src = socket_source(tree, inputs["Emission"])
    emission_val = tuple(inputs["Emission"].default_value)
    strength = inputs["Emission Strength"].default_value
    if emission_src is not None or (max(emission_val[:3]) > 0 and strength > 0):
        emission = nodes.new("ShaderNodeEmission")
        feed(tree, emission_src, emission.inputs["Color"], emission_val)
        emission.inputs["Strength"].default_value = strength
        add = nodes.new("ShaderNodeAddShader")
        links.new(result, add.inputs[0])
        links.new(emission.outputs[0], add.inputs[1])
        result = add.outputs[0]

    alpha_src = socket_source(tree, inputs["Alpha"])
    alpha_val = inputs["Alpha"].default_value
    if alpha_src is not None or alpha_val < 1.0:
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        mix = nodes.new("ShaderNodeMixShader")
        feed(tree, alpha_src, mix.inputs["Fac"], alpha_val)
        links.new(transparent.outputs[0], mix.inputs[1])
        links.new(result, mix.inputs[2])
        result = mix.outputs[0]
    links.new(result, out.inputs["Surface"])
    return f"Appendix B graph, {LOBES} lobes (F0 {f0:.4f}, specularFactor {s:g})"


def import_model(path, doc, raw, scratch):
    copy = renamed_copy(path, doc, raw, scratch)
    bpy.ops.import_scene.gltf(
        filepath=str(copy),
        merge_vertices=False,
        import_shading="NORMALS",
        convert_lighting_mode="SPEC",
    )
    order = scene_nodes(doc)
    keep = {f"N{i}" for i, _ in order}
    # The importer makes every node of every scene; keep the default scene's.
    for obj in list(bpy.data.objects):
        if obj.name.split(".")[0] not in keep and obj.type != "ARMATURE":
            bpy.data.objects.remove(obj)
    # No animation: the file's rest state (node TRS, mesh weights) is what Glint renders.
    for obj in bpy.data.objects:
        obj.animation_data_clear()
        if obj.type == "MESH" and obj.data.shape_keys:
            obj.data.shape_keys.animation_data_clear()
    for i, _ in order:
        node = doc["nodes"][i]
        if "mesh" not in node:
            continue
        weights = node.get("weights", doc["meshes"][node["mesh"]].get("weights", []))
        obj = bpy.data.objects.get(f"N{i}")
        if obj is not None and obj.type == "MESH" and obj.data.shape_keys:
            blocks = obj.data.shape_keys.key_blocks[1:]
            for j, block in enumerate(blocks):
                block.value = weights[j] if j < len(weights) else 0.0
    # glTF reads a texture's RGB as it is and its alpha on its own; Blender's default for a
    # PNG with alpha (straight alpha, premultiplied when sampled) would blacken RGB where
    # alpha is 0 and darken it elsewhere, on OPAQUE materials too.
    for image in bpy.data.images:
        image.alpha_mode = "CHANNEL_PACKED"
    # Primitives without a material get glTF's default material.
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        mesh = obj.data
        colours = [a.name for a in mesh.color_attributes]
        vc = "Col" if "Col" in colours else None
        for slot in range(len(mesh.materials)):
            if mesh.materials[slot] is None:
                mesh.materials[slot] = default_material(vc)
        if len(mesh.materials) == 0:
            mesh.materials.append(default_material(vc))
    return order


def camera_from_gltf(position, axes, yfov):
    """A Blender camera at glTF `position` with glTF camera axes (right, up, back)."""
    data = bpy.data.cameras.new("reference")
    data.sensor_fit = "VERTICAL"
    data.angle_y = yfov
    data.clip_start = 1e-4
    data.clip_end = 1e6
    obj = bpy.data.objects.new("reference camera", data)
    bpy.context.scene.collection.objects.link(obj)
    u, v, w = (Vector(a).normalized() for a in axes)
    m = Matrix.Identity(4)
    for r in range(3):
        m[r][0], m[r][1], m[r][2], m[r][3] = u[r], v[r], w[r], position[r]
    obj.matrix_world = TO_BLENDER @ m
    bpy.context.scene.camera = obj
    return obj


def set_camera(doc, order):
    """The file's camera (first node in depth-first order with one), else Glint's framing
    camera. Returns the manifest's record."""
    for i, world in order:
        node = doc["nodes"][i]
        if "camera" not in node:
            continue
        cam = doc["cameras"][node["camera"]]
        if cam.get("type") != "perspective":
            continue
        yfov = cam["perspective"]["yfov"]
        position = world.to_translation()
        axes = [world.col[c].to_3d() for c in range(3)]
        obj = camera_from_gltf(position, axes, yfov)
        # Check the importer's conversion of the same camera against the file's.
        imported = bpy.data.objects.get(f"N{i}")
        agreement = None
        if imported is not None and imported.type == "CAMERA":
            a = imported.matrix_world.normalized()
            b = obj.matrix_world.normalized()
            agreement = max(abs(a[r][c] - b[r][c]) for r in range(3) for c in range(4))
        eye = tuple(position)
        forward = tuple(-axes[2].normalized())
        return {
            "kind": "file",
            "node": i,
            "yfov_degrees": math.degrees(yfov),
            "eye": eye,
            "forward": forward,
            "up": tuple(axes[1].normalized()),
            "importer_matrix_difference": agreement,
        }
    # Framing camera: the world-space AABB of all triangle vertices, in glTF coordinates.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    points = []
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        used = {v for p in mesh.polygons for v in p.vertices}
        for index in used:
            points.append(to_gltf(evaluated.matrix_world @ mesh.vertices[index].co))
        evaluated.to_mesh_clear()
    pts = np.array(points, dtype=np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c = (lo + hi) / 2
    r = float(np.linalg.norm(hi - lo) / 2) or 1.0
    vfov = math.radians(FRAMING_FOV)
    hfov = 2 * math.atan(math.tan(vfov / 2) * WIDTH / HEIGHT)
    theta = min(vfov, hfov)
    d = r / math.sin(theta / 2)
    n = np.array([1.0, 1.0, 2.0]) / math.sqrt(6.0)
    eye = c + d * n
    back = n
    right = np.cross([0.0, 1.0, 0.0], back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    camera_from_gltf(Vector(eye), [Vector(right), Vector(up), Vector(back)], vfov)
    return {
        "kind": "framing",
        "aabb_min": lo.tolist(),
        "aabb_max": hi.tolist(),
        "center": c.tolist(),
        "radius": r,
        "distance": d,
        "yfov_degrees": FRAMING_FOV,
        "eye": eye.tolist(),
        "forward": (-n).tolist(),
        "up": up.tolist(),
    }


def set_world(scene, doc):
    """White sky of radiance 1 unless the file brings light: a punctual light of positive
    intensity or an emissive material (Glint's importer counts both), then black."""
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    lit = any(light.get("intensity", 1.0) > 0 for light in lights)
    used = {
        p.get("material")
        for m in doc.get("meshes", [])
        for p in m.get("primitives", [])
        if p.get("material") is not None
    }
    for index in used:
        m = doc["materials"][index]
        strength = (
            m.get("extensions", {})
            .get("KHR_materials_emissive_strength", {})
            .get("emissiveStrength", 1.0)
        )
        if max(m.get("emissiveFactor", [0, 0, 0])) * strength > 0:
            lit = True
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    sky = 0.0 if lit else 1.0
    background.inputs["Color"].default_value = (sky, sky, sky, 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.world = world
    for obj in bpy.data.objects:
        if obj.type == "LIGHT":
            obj.data.shadow_soft_size = 0.0  # punctual
            if obj.data.type == "SUN":
                obj.data.angle = 0.0
    return sky


def cycles_common(scene):
    c = scene.cycles
    c.device = "CPU"
    c.use_denoising = False
    scene.view_layers[0].cycles.use_denoising = False
    c.use_adaptive_sampling = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.use_animated_seed = False
    c.film_exposure = 1.0
    c.film_transparent = False
    scene.render.threads_mode = "AUTO"
    scene.render.use_persistent_data = False


def render_to(scene, path):
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "NONE"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return exr_io.read_exr(str(path))


def channel(data, suffix):
    for name, values in data.items():
        if name.endswith(suffix):
            return values
    raise KeyError(f"{suffix} not among {sorted(data)}")


def render_layers(scene, doc, scratch):
    """Pixel-centre layers through AOVs (module docs)."""
    layer = scene.view_layers[0]
    for name, kind in (
        ("albedo", "COLOR"),
        ("normal", "COLOR"),
        ("depth", "VALUE"),
        ("excluded", "VALUE"),
    ):
        aov = layer.aovs.add()
        aov.name = name
        aov.type = kind
    for mat in list(bpy.data.materials):
        if mat.use_nodes:
            add_aovs(scene, mat, doc)
    c = scene.cycles
    c.samples = 1
    c.seed = 0
    c.pixel_filter_type = "BOX"
    c.filter_width = 0.01
    c.max_bounces = 0
    c.transparent_max_bounces = 64
    data = render_to(scene, scratch / "layers.exr")
    albedo = np.stack([channel(data, f"albedo.{ch}") for ch in "RGB"], -1)
    normal_b = np.stack([channel(data, f"normal.{ch}") for ch in "RGB"], -1)
    depth = channel(data, "depth.X")
    excluded = channel(data, "excluded.X")
    # EXR rows run top to bottom, as Glint's film.
    normal = np.stack([normal_b[..., 0], normal_b[..., 2], -normal_b[..., 1]], -1)
    escaped = depth <= 0
    albedo = np.clip(albedo, 0.0, 1.0)
    albedo[escaped] = (
        1.0
        if scene.world.node_tree.nodes["Background"].inputs["Color"].default_value[0]
        > 0
        else 0.0
    )
    normal[escaped] = 0.0
    return albedo, normal, depth, excluded > 0


def volume_absorption(doc):
    """KHR_materials_volume's attenuation is sigma = -ln(attenuationColor) /
    attenuationDistance; the importer gives Cycles' Volume Absorption colour =
    attenuationColor and density = 1 / attenuationDistance, where Cycles absorbs
    sigma = density * (1 - colour). Set colour and density to give glTF's sigma."""
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        ext = material_info(doc, mat).get("extensions", {})
        volume = ext.get("KHR_materials_volume", {})
        distance = volume.get("attenuationDistance")
        if distance is None:
            continue
        colour = volume.get("attenuationColor", [1.0, 1.0, 1.0])
        sigma = [-math.log(max(c, 1e-6)) / distance for c in colour]
        density = max(max(sigma), 1e-6)
        for node in mat.node_tree.nodes:
            if node.type == "VOLUME_ABSORPTION":
                node.inputs["Density"].default_value = density
                rgb = [1 - s / density for s in sigma]
                node.inputs["Color"].default_value = (*rgb, 1)


def render_beauty(scene, doc, spp, scratch):
    volume_absorption(doc)
    notes = sorted(
        {appendix_b_graph(m, doc) for m in bpy.data.materials if m.use_nodes}
    )
    c = scene.cycles
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = 64
    c.diffuse_bounces = 64
    c.glossy_bounces = 64
    c.transmission_bounces = 64
    c.volume_bounces = 16
    c.transparent_max_bounces = 64
    halves = []
    start = time.time()
    for seed in (1, 2):
        c.samples = spp // 2
        c.seed = seed
        data = render_to(scene, scratch / f"beauty{seed}.exr")
        halves.append(np.stack([channel(data, f"Combined.{ch}") for ch in "RGB"], -1))
    seconds = time.time() - start
    mean = (halves[0] + halves[1]) / 2
    # The reference's own noise in compare.rs's relMSE units: E[relMSE(h1, h2)] = 4 sigma^2.
    noise = float(np.mean((halves[0] - halves[1]) ** 2 / (mean**2 + 0.01)) / 4)
    return mean, noise, notes, seconds


def beauty_rule(doc):
    """Whether Glint's beauty is held to this reference ('tested') or only shown on the
    contact sheet, and why: tested are models whose every material is metal-only
    (metallic 1, untextured metallic) or diffuse-only (metallic 0, specularFactor 0), opaque,
    unlit by punctual lights, without emission, transmission or clearcoat."""
    if doc.get("extensions", {}).get("KHR_lights_punctual"):
        return "contact-sheet", "punctual lights (spot cone falloff differs)"
    meshes = doc.get("meshes", [])
    used = {p.get("material") for m in meshes for p in m.get("primitives", [])}
    kinds = set()
    for index in used:
        m = {} if index is None else doc["materials"][index]
        pbr = m.get("pbrMetallicRoughness", {})
        ext = m.get("extensions", {})
        if m.get("alphaMode", "OPAQUE") != "OPAQUE":
            return "contact-sheet", f"material {index}: alpha mode"
        if any(
            k in ext
            for k in (
                "KHR_materials_transmission",
                "KHR_materials_clearcoat",
                "KHR_materials_volume",
            )
        ):
            return "contact-sheet", f"material {index}: transmission/clearcoat"
        if max(m.get("emissiveFactor", [0, 0, 0])) > 0:
            return "contact-sheet", f"material {index}: emission"
        metallic = pbr.get("metallicFactor", 1.0)
        if "metallicRoughnessTexture" in pbr:
            return "contact-sheet", f"material {index}: metallic-roughness texture"
        diffuse = ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0) == 0
        if not (metallic == 1.0 or (metallic == 0.0 and diffuse)):
            return "contact-sheet", f"material {index}: dielectric with a specular lobe"
        kinds.add("metal" if metallic == 1.0 else "diffuse")
    if kinds == {"diffuse"}:
        return "tested", "diffuse-only"
    if kinds == {"metal"}:
        return "tested", "metal-only"
    return "tested", "metal and diffuse materials"


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    spp, only = 1024, set()
    i = 0
    while i < len(argv):
        if argv[i] == "--spp":
            spp = int(argv[i + 1])
            i += 2
        elif argv[i] == "--only":
            only.update(argv[i + 1].split(","))
            i += 2
        else:
            raise SystemExit(f"unknown argument {argv[i]}")
    OUT.mkdir(parents=True, exist_ok=True)
    manifest_path = OUT / "manifest.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.exists() else {}
    entries = {e["model"]: e for e in manifest.get("models", [])}
    print(f"k(mu) fit: degree {len(K_FIT) - 1}, worst error {K_FIT_ERROR:.2e}")
    for name, relative in models():
        if only and name not in only:
            continue
        path = (REPO / relative).resolve()
        doc, raw = read_document(path)
        scene = reset()
        cycles_common(scene)
        with tempfile.TemporaryDirectory() as tmp:
            scratch = Path(tmp)
            order = import_model(path, doc, raw, scratch)
            camera = set_camera(doc, order)
            sky = set_world(scene, doc)
            bpy.ops.wm.save_as_mainfile(filepath=str(scratch / "scene.blend"))
            albedo, normal, depth, excluded = render_layers(scene, doc, scratch)
            # Re-open the file as imported (no AOV nodes) for the beauty.
            bpy.ops.wm.open_mainfile(filepath=str(scratch / "scene.blend"))
            scene = bpy.context.scene
            beauty, noise, notes, seconds = render_beauty(scene, doc, spp, scratch)
        channels = {
            "R": (beauty[..., 0], "half"),
            "G": (beauty[..., 1], "half"),
            "B": (beauty[..., 2], "half"),
            "albedo.R": (albedo[..., 0], "half"),
            "albedo.G": (albedo[..., 1], "half"),
            "albedo.B": (albedo[..., 2], "half"),
            "normal.X": (normal[..., 0], "half"),
            "normal.Y": (normal[..., 1], "half"),
            "normal.Z": (normal[..., 2], "half"),
            "depth.Z": (depth, "float"),
        }
        if excluded.any():
            channels["mask"] = ((~excluded).astype(np.float32), "half")
        exr_io.write_exr(
            str(OUT / f"{name}.exr"),
            channels,
            {
                "source": relative,
                "renderer": f"Blender {bpy.app.version_string} Cycles",
            },
        )
        status, reason = beauty_rule(doc)
        entries[name] = {
            "model": name,
            "path": relative,
            "reference": f"{name}.exr",
            "width": WIDTH,
            "height": HEIGHT,
            "layers": ["depth", "normal", "albedo"],
            "layers_excluded_pixels": int(excluded.sum()),
            "beauty": status,
            "beauty_reason": reason,
            "beauty_spp": spp,
            "beauty_noise_relmse": noise,
            "beauty_seconds": round(seconds, 1),
            "sky_radiance": sky,
            "camera": camera,
            "materials": notes,
        }
        print(
            f"REF {name}: camera {camera['kind']}, beauty {status} ({reason}), "
            f"noise {noise:.2e}, {seconds:.0f} s, {notes}"
        )
    manifest = {
        "blender": bpy.app.version_string,
        "k_fit_worst_error": K_FIT_ERROR,
        "models": [entries[k] for k in sorted(entries)],
    }
    manifest_path.write_text(json.dumps(manifest, indent=1) + "\n")


if __name__ == "__main__":
    main()
