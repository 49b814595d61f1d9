"""Shapes, dtypes, crops, settings and errors of `glint.render` and friends."""

from __future__ import annotations

import json
import pickle
import warnings

import numpy as np
import pytest
from conftest import EXR_CHANNELS, EXR_DEPTH, THREE_SPHERES, read_exr

import glint


@pytest.fixture(scope="module")
def spheres() -> glint.Scene:
    return glint.load_scene(THREE_SPHERES)


def bits(array: np.ndarray) -> np.ndarray:
    """The float32 values as their bit patterns, so equality is bit-for-bit (and NaN == NaN)."""
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


@pytest.mark.parametrize("integrator", glint.INTEGRATORS)
def test_every_integrator_gives_a_float32_height_width_3_array(spheres, integrator):
    image = glint.render(spheres, width=24, height=16, spp=2, integrator=integrator)
    assert image.shape == (16, 24, 3)
    assert image.dtype == np.float32
    assert image.flags.c_contiguous
    assert np.isfinite(image).all()
    # Not a blank image: the spheres and the floor make the pixels differ.
    assert image.std() > 0.01


def test_features_give_the_layers_and_the_same_beauty(spheres):
    plain = glint.render(spheres, width=20, height=12, spp=4, integrator="path", seed=3)
    layers = glint.render(
        spheres, width=20, height=12, spp=4, integrator="path", seed=3, features=True
    )
    assert sorted(layers) == ["albedo", "beauty", "depth", "normal"]
    for name in ("beauty", "albedo", "normal"):
        assert layers[name].shape == (12, 20, 3) and layers[name].dtype == np.float32
    assert layers["depth"].shape == (12, 20) and layers["depth"].dtype == np.float32
    assert np.array_equal(bits(layers["beauty"]), bits(plain))
    # Means of unit normals (zero where a sample sees the sky): at most unit length, and unit
    # length or zero wherever every sample of a pixel sees the same flat floor or the sky.
    lengths = np.linalg.norm(layers["normal"], axis=2)
    assert np.all(lengths <= 1 + 1e-5)
    assert np.mean((np.abs(lengths - 1) < 1e-3) | (lengths == 0)) > 0.5
    assert (layers["depth"] > 0).any()


@pytest.mark.parametrize(
    "crop",
    [np.s_[0:7, 0:9], np.s_[5:16, 9:24], np.s_[-5:, 3:-3], np.s_[:, 10:11], np.s_[2:3, :100]],
)
def test_a_crop_is_the_same_pixels_as_that_part_of_the_whole_image(spheres, crop):
    settings = dict(width=24, height=16, spp=4, integrator="path", seed=11)
    whole = glint.render(spheres, **settings)
    part = glint.render(spheres, crop=crop, **settings)
    assert part.shape == whole[crop].shape
    assert np.array_equal(bits(part), bits(whole[crop]))


def test_the_image_does_not_depend_on_the_thread_count(spheres):
    settings = dict(width=40, height=24, spp=4, integrator="path", seed=5)
    one = glint.render(spheres, threads=1, **settings)
    two = glint.render(spheres, threads=2, **settings)
    assert np.array_equal(bits(one), bits(two))


def test_the_seed_changes_the_noise_but_not_the_picture(spheres):
    a = glint.render(spheres, width=24, height=16, spp=4, integrator="path", seed=1)
    b = glint.render(spheres, width=24, height=16, spp=4, integrator="path", seed=2)
    assert not np.array_equal(a, b)
    # Mean absolute difference between two 4-sample estimates of the same image: noise only.
    assert np.abs(a.mean() - b.mean()) < 0.05


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(integrator="whitted"), ValueError, "course, path, volpath, normals, albedo, depth"),
        (dict(spp=0), ValueError, "spp"),
        (dict(width=0), ValueError, "width must be between 1 and 65535, got 0"),
        (dict(width=70000), ValueError, "width must be between 1 and 65535, got 70000"),
        (dict(max_depth=101), ValueError, "max_depth must be between 0 and 100, got 101"),
        (dict(threads=0), ValueError, "threads"),
        (dict(aspect=-1.0), ValueError, "aspect"),
        (dict(crop=(0, 4, 0, 4)), TypeError, "pair of slices"),
        (dict(crop=np.s_[0:4:2, 0:4]), ValueError, "step 1"),
        (dict(crop=np.s_[4:4, 0:4]), ValueError, "empty"),
        (dict(spp=-1), ValueError, "spp must be between 1 and 16777216, got -1"),
    ],
)
def test_bad_settings_raise_before_rendering(spheres, kwargs, error, words):
    settings = dict(width=8, height=8)
    settings.update(kwargs)
    with pytest.raises(error, match=words):
        glint.render(spheres, **settings)


def test_scene_errors_carry_file_line_column_and_the_cli_message(tmp_path):
    path = tmp_path / "bad.xml"
    path.write_text(
        '<scene>\n  <shape type="sphere">\n    <radius>-1</radius>\n  </shape>\n</scene>\n'
    )
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(path)
    error = caught.value
    assert isinstance(error, ValueError)
    assert (error.file, error.line, error.column) == (str(path), 3, 13)
    assert "radius" in error.message
    # The text is the CLI's: location, message, the offending line and a caret under column 13.
    lines = str(error).splitlines()
    assert lines[0] == f"{path}:3:13: {error.message}"
    assert lines[1] == "    <radius>-1</radius>"
    assert lines[2] == " " * 12 + "^"
    # Exceptions travel between processes (Dask) by pickle, attributes included.
    again = pickle.loads(pickle.dumps(error))
    assert (again.file, again.line, again.column, again.message, str(again)) == (
        error.file,
        error.line,
        error.column,
        error.message,
        str(error),
    )


def test_every_missing_asset_is_named_at_once(tmp_path):
    path = tmp_path / "two.xml"
    path.write_text(
        '<scene><camera name="main" type="perspective"><position>0 0 5</position></camera>\n'
        '  <shape type="mesh"><file>a.obj</file></shape>\n'
        '  <shape type="mesh"><file>b.obj</file></shape>\n'
        "</scene>\n"
    )
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(path)
    error = caught.value
    # Located at the first; the text names both, each with the path tried.
    assert (error.file, error.line) == (str(path), 2)
    text = str(error)
    assert f"(tried {tmp_path / 'a.obj'})" in text
    assert f"(tried {tmp_path / 'b.obj'})" in text
    assert str(pickle.loads(pickle.dumps(error))) == text


def test_text_and_dict_errors_point_into_the_text():
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene_text('{"scene": {\n  "bgColor": "1 2"\n}}', base_dir="assets")
    assert caught.value.file.endswith("<text>.json")
    assert caught.value.file.startswith("assets")
    assert (caught.value.line, caught.value.column) == (2, 14)

    scene = {"scene": {**glint.BALL["scene"], "bgColor": "0.2 0.2"}}
    with pytest.raises(glint.SceneError) as caught:
        glint.scene_from_dict(scene, name="ball.json")
    # The dict is written as indented JSON; the message shows the line it means.
    assert caught.value.file == "ball.json"
    assert '"bgColor": "0.2 0.2"' in str(caught.value).splitlines()[1]


def test_missing_files_raise_file_not_found():
    with pytest.raises(FileNotFoundError) as caught:
        glint.load_scene("no/such/scene.json")
    assert caught.value.filename == "no/such/scene.json"


def test_format_must_match_the_text():
    with pytest.raises(ValueError, match="starts with '<'"):
        glint.load_scene_text("<scene/>", format="json")
    with pytest.raises(ValueError, match="format must be"):
        glint.load_scene_text("{}", format="yaml")


def test_warnings_are_python_warnings_with_locations(tmp_path):
    path = tmp_path / "odd.json"
    scene = {"scene": {**glint.BALL["scene"], "bgColour": "1 0 0"}}
    path.write_text(json.dumps(scene, indent=1))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        loaded = glint.load_scene(path)
    messages = [w.message for w in caught if issubclass(w.category, glint.SceneWarning)]
    assert len(messages) == 1
    warning = messages[0]
    assert warning.file == str(path)
    assert "bgColour" in warning.message
    line = path.read_text().splitlines()[warning.line - 1]
    assert line.find('"bgColour"') == warning.column - 1
    assert str(warning).startswith(f"{path}:{warning.line}:{warning.column}: ")
    # Shown as raised by the caller (this file), not by glint's own code.
    assert [w.filename for w in caught] == [__file__]
    # Kept on the scene too.
    assert [str(w) for w in loaded.warnings] == [str(warning)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(glint.SceneWarning):
            glint.load_scene(path)


def test_a_scene_pickles_as_its_source_and_renders_the_same(tmp_path, spheres):
    settings = dict(width=16, height=12, spp=4, integrator="path", seed=9)
    for scene in (spheres, glint.scene_from_dict(glint.BALL)):
        again = pickle.loads(pickle.dumps(scene))
        assert again.name.endswith(scene.name.lstrip("."))
        assert np.array_equal(
            bits(glint.render(again, **settings)), bits(glint.render(scene, **settings))
        )
    assert repr(spheres) == f'<glint.Scene "{THREE_SPHERES}">'


def test_background_replaces_the_scenes_and_survives_pickling():
    grey = glint.scene_from_dict(glint.BALL, background=(0.5, 0.25, 0))
    corner = glint.render(grey, width=8, height=8)[0, 0]
    assert corner.tolist() == [0.5, 0.25, 0.0]
    again = pickle.loads(pickle.dumps(grey))
    assert glint.render(again, width=8, height=8)[0, 0].tolist() == [0.5, 0.25, 0.0]
    plain = glint.render(glint.scene_from_dict(glint.BALL), width=8, height=8)[0, 0]
    assert np.allclose(plain, 0.2)  # the scene's own bgColor
    for bad in [(-1, 0, 0), (float("nan"), 0, 0)]:
        with pytest.raises(ValueError, match="background"):
            glint.scene_from_dict(glint.BALL, background=bad)
    with pytest.raises(ValueError):
        glint.load_scene(THREE_SPHERES, background=(1, 2))


def test_to_srgb8_known_values():
    linear = np.array([[[0.0, 0.18, 1.0], [-1.0, np.nan, 1e9], [0.0031308, 0.5, 0.2158605]]])
    assert glint.to_srgb8(linear).tolist() == [[[0, 118, 255], [0, 0, 255], [10, 188, 128]]]
    assert glint.to_srgb8(np.full((1, 1, 3), 0.045), exposure=2).tolist() == [[[118] * 3]]
    assert glint.to_srgb8(np.full((1, 1, 3), 0.72), exposure=-2).tolist() == [[[118] * 3]]


def test_write_image_writes_what_render_returned(tmp_path, spheres):
    layers = glint.render(spheres, width=20, height=10, spp=4, features=True)
    glint.write_image(tmp_path / "all.exr", layers)
    glint.write_image(tmp_path / "beauty.exr", layers["beauty"])
    everything = read_exr(tmp_path / "all.exr")
    assert sorted(everything) == sorted(
        [name for names in EXR_CHANNELS.values() for name in names] + [EXR_DEPTH]
    )
    for layer, names in EXR_CHANNELS.items():
        stacked = np.stack([everything[name] for name in names], axis=2)
        assert np.array_equal(bits(stacked), bits(layers[layer]))
    assert np.array_equal(bits(everything[EXR_DEPTH]), bits(layers["depth"]))
    assert sorted(read_exr(tmp_path / "beauty.exr")) == ["B", "G", "R"]

    # PNG: the course's conversion, floor(clamp(c) * 255), no gamma.
    glint.write_image(tmp_path / "beauty.png", layers["beauty"].astype(np.float64))
    png = (tmp_path / "beauty.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_write_image_refuses_bad_input_and_leaves_no_file(tmp_path):
    image = np.zeros((4, 4, 3), np.float32)
    with pytest.raises(ValueError, match="unsupported image format"):
        glint.write_image(tmp_path / "x.jpg", image)
    with pytest.raises(ValueError, match="shape"):
        glint.write_image(tmp_path / "x.exr", np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="go together"):
        glint.write_image(tmp_path / "x.exr", {"beauty": image, "depth": image[..., 0]})
    with pytest.raises(FileNotFoundError) as caught:
        glint.write_image(tmp_path / "missing" / "x.exr", image)
    assert caught.value.filename == str(tmp_path / "missing" / "x.exr")
    assert list(tmp_path.iterdir()) == []
