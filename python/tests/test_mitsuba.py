"""Mitsuba 3 scenes from Python: their film, sampler and integrator are `glint.render`'s defaults,
as they are the CLI's without flags; `defines` are the CLI's `-D`; and the pixels are the CLI's."""

from __future__ import annotations

import pickle
import subprocess

import numpy as np
import pytest
from conftest import EXR_CHANNELS, EXR_DEPTH, THREE_SPHERES, read_exr

import glint

# A diffuse sphere on a diffuse floor under a rectangular area light; the film is `res` x `res`
# (8 unless defined), 4 samples, the path tracer at Mitsuba's max_depth 3 (Glint's depth 2).
SCENE = """<scene version="3.0.0">
  <default name="res" value="8"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,1,5" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm">
      <integer name="width" value="$res"/>
      <integer name="height" value="$res"/>
    </film>
  </sensor>
  <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.5"/></bsdf>
  <shape type="rectangle">
    <transform name="to_world">
      <rotate x="1" angle="-90"/><scale value="3"/><translate y="-1"/>
    </transform>
    <ref id="grey"/>
  </shape>
  <shape type="sphere">
    <float name="radius" value="0.8"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.2,0.2"/></bsdf>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><rotate x="1" angle="90"/><translate y="2.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="4"/></emitter>
  </shape>
</scene>
"""


def bits(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "mitsuba.xml"
    path.write_text(SCENE)
    return path


def test_the_scene_chooses_size_samples_integrator_and_depth(scene_file):
    scene = glint.load_scene(scene_file)
    assert scene.render_settings() == {
        "width": 8,
        "height": 8,
        "spp": 4,
        "integrator": "path",
        "max_depth": 2,
    }
    image = glint.render(scene)
    assert image.shape == (8, 8, 3)
    # The scene's settings given by hand are the same render, bit for bit.
    same = glint.render(scene, width=8, height=8, spp=4, integrator="path", max_depth=2)
    assert np.array_equal(bits(image), bits(same))
    # It is the scene's sample count, not one sample: one sample is another image.
    one = glint.render(scene, spp=1)
    assert not np.array_equal(bits(image), bits(one))
    # And its depth: an unbounded path is another image (light bounces off floor and sphere).
    deep = glint.render(scene, max_depth=50)
    assert not np.array_equal(bits(image), bits(deep))


def test_arguments_win_over_the_scene(scene_file):
    scene = glint.load_scene(scene_file)
    settled = scene.render_settings(width=6, height=5, spp=9, integrator="normals", max_depth=7)
    assert settled == {"width": 6, "height": 5, "spp": 9, "integrator": "normals", "max_depth": 7}
    assert glint.render(scene, width=6, height=5).shape == (5, 6, 3)
    # Another integrator keeps its own depth: the scene's counts the path tracer's bounces.
    assert scene.render_settings(integrator="course")["max_depth"] is None
    # A crop is taken in the scene's own image size.
    whole = glint.render(scene)
    corner = glint.render(scene, crop=np.s_[4:8, 0:4])
    assert np.array_equal(bits(corner), bits(whole[4:8, 0:4]))


def test_defines_change_the_size_and_survive_pickling(scene_file):
    scene = glint.load_scene(scene_file, defines={"res": "12"})
    assert glint.render(scene, spp=1).shape == (12, 12, 3)
    again = pickle.loads(pickle.dumps(scene))
    assert again.render_settings()["width"] == 12
    text = glint.load_scene_text(SCENE, format="xml", defines={"res": "3"})
    assert text.render_settings()["height"] == 3


def test_a_bad_define_is_a_located_scene_error(scene_file):
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(scene_file, defines={"res": "wide"})
    error = caught.value
    # Where `$res` is used, as the CLI points at it.
    line = next(i for i, text in enumerate(SCENE.splitlines(), 1) if 'value="$res"' in text)
    assert (error.file, error.line) == (str(scene_file), line)
    assert error.column > 1
    assert str(error).startswith(f"{scene_file}:{line}:{error.column}: ")
    with pytest.raises(TypeError, match="str to str"):
        glint.load_scene(scene_file, defines={"res": 12})


def test_course_scenes_keep_the_course_defaults():
    assert glint.load_scene(THREE_SPHERES).render_settings() == {
        "width": 100,
        "height": 100,
        "spp": 1,
        "integrator": "course",
        "max_depth": None,
    }


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        ([], {}),
        (
            ["-w", "10", "-h", "6", "-r", "3", "--seed", "5"],
            dict(width=10, height=6, spp=3, seed=5),
        ),
        (["-D", "res=5", "-k", "1"], dict(defines={"res": "5"}, max_depth=1)),
    ],
)
def test_render_returns_the_cli_exr_pixels(cli, scene_file, tmp_path, flags, kwargs):
    output = tmp_path / "cli.exr"
    command = [str(cli), "render", str(scene_file), "-o", str(output), "-n", "2", *flags]
    subprocess.run(command, check=True, capture_output=True)
    written = read_exr(output)
    defines = kwargs.pop("defines", None)
    scene = glint.load_scene(scene_file, defines=defines)
    layers = glint.render(scene, features=True, **kwargs)  # the CLI's EXR has the layers
    for layer, names in EXR_CHANNELS.items():
        from_cli = np.stack([written[name] for name in names], axis=2)
        assert np.array_equal(bits(layers[layer]), bits(from_cli)), layer
    assert np.array_equal(bits(layers["depth"]), bits(written[EXR_DEPTH]))
