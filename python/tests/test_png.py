"""`glint.write_image` writes the PNG `glint render` writes for the same image and options."""

from __future__ import annotations

import pickle
import struct
import subprocess
import warnings
import zlib

import numpy as np
import pytest
from conftest import THREE_SPHERES

import glint

# The CLI's PNG also holds the render's own facts (scene hash, seed, time, rays...) as tEXt
# chunks, which an array does not carry; every other chunk must be the same, byte for byte.
SHARED_TEXT = {b"Software", b"Glint output transform", b"Glint transfer function"}


def chunks(png: bytes) -> list[tuple[bytes, bytes]]:
    """The PNG's chunks, (type, data), in order, with every CRC checked."""
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    found, at = [], 8
    while at < len(png):
        (length,) = struct.unpack(">I", png[at : at + 4])
        kind, data = png[at + 4 : at + 8], png[at + 8 : at + 8 + length]
        (crc,) = struct.unpack(">I", png[at + 8 + length : at + 12 + length])
        assert crc == zlib.crc32(kind + data)
        found.append((kind, data))
        at += 12 + length
    return found


def comparable(png: bytes) -> list[tuple[bytes, bytes]]:
    return [
        (kind, data)
        for kind, data in chunks(png)
        if kind != b"tEXt" or data.split(b"\0", 1)[0] in SHARED_TEXT
    ]


SIZE = dict(width=30, height=20, spp=4)


def cli_png(cli, tmp_path, integrator: str, options: dict) -> bytes:
    output = tmp_path / "cli.png"
    command = [str(cli), "render", str(THREE_SPHERES), "-o", str(output), "-n", "2"]
    command += ["-w", str(SIZE["width"]), "-h", str(SIZE["height"]), "-r", str(SIZE["spp"])]
    command += ["--integrator", integrator]
    for name, value in options.items():
        command += [f"--{name}", str(value)]
    subprocess.run(command, check=True, capture_output=True)
    return output.read_bytes()


@pytest.mark.parametrize(
    "integrator, options",
    [
        ("path", {}),
        ("course", {}),
        ("albedo", {}),
        ("normals", {}),
        ("path", {"exposure": 1.5}),
        ("path", {"tonemap": "aces", "transfer": "linear"}),
        ("course", {"tonemap": "agx"}),
        ("path", {"exposure": -2, "tonemap": "none"}),
    ],
)
def test_the_png_of_a_render_is_the_clis(cli, tmp_path, integrator, options):
    expected = cli_png(cli, tmp_path, integrator, options)
    scene = glint.load_scene(THREE_SPHERES)
    image = glint.render(scene, integrator=integrator, **SIZE)
    # The obvious call: the image knows how it was made.
    glint.write_image(tmp_path / "py.png", image, **options)
    written = (tmp_path / "py.png").read_bytes()
    assert comparable(written) == comparable(expected)
    # A plain array, told the integrator.
    plain = np.array(image)
    glint.write_image(tmp_path / "plain.png", plain, integrator=integrator, **options)
    assert comparable((tmp_path / "plain.png").read_bytes()) == comparable(expected)


def test_a_path_traced_png_is_srgb_and_a_course_png_is_not(tmp_path):
    scene = glint.load_scene(THREE_SPHERES)
    for integrator, srgb in (("path", True), ("course", False)):
        glint.write_image(tmp_path / "x.png", glint.render(scene, integrator=integrator, **SIZE))
        kinds = [kind for kind, _ in chunks((tmp_path / "x.png").read_bytes())]
        assert (b"sRGB" in kinds) == srgb, integrator


def test_the_integrator_survives_slicing_arithmetic_features_and_pickling():
    scene = glint.scene_from_dict(glint.BALL)
    image = glint.render(scene, width=8, height=8, integrator="path")
    assert isinstance(image, glint.Image) and image.integrator == "path"
    assert (image[2:6] * 2.0).integrator == "path"
    assert pickle.loads(pickle.dumps(image)).integrator == "path"
    assert np.array_equal(pickle.loads(pickle.dumps(image)), image)
    layers = glint.render(scene, width=8, height=8, integrator="albedo", features=True)
    assert layers["beauty"].integrator == "albedo"
    assert glint.render(scene, width=8, height=8).integrator == "course"


def test_display_options_on_an_exr_warn_that_they_do_nothing(tmp_path):
    image = glint.render(glint.scene_from_dict(glint.BALL), width=4, height=4)
    with pytest.warns(UserWarning, match="no effect on an EXR"):
        glint.write_image(tmp_path / "x.exr", image, exposure=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        glint.write_image(tmp_path / "y.exr", image)
