"""glTF 2.0 models: `.glb` and `.gltf` with external buffers load and render, `scene=` and
`camera=` choose as the CLI's `--scene` and `--camera` do, and `env=` lights a model as `--env`."""

from __future__ import annotations

import pickle
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, _missing, read_exr

import glint

# The project's shared glTF test files (SOURCES.md there: Box and BoxTextured are Cesium's,
# CC-BY-4.0; MultipleScenes is CC0), read in place rather than copied into the repository.
MODELS = REPO.parent / "shared" / "gltf"


@pytest.fixture(scope="module")
def models() -> Path:
    if not MODELS.is_dir():
        _missing(f"the shared glTF models ({MODELS})")
    return MODELS


def quiet_load(path, **kwargs) -> glint.Scene:
    """Loads a model without a camera or light, whose warnings say how it is framed and lit."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", glint.SceneWarning)
        return glint.load_scene(path, **kwargs)


def bits(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


def test_a_glb_loads_and_renders_with_the_path_tracer(models):
    with pytest.warns(glint.SceneWarning) as caught:
        scene = glint.load_scene(models / "BoxTextured-GLB" / "BoxTextured.glb")
    # No camera and no light in the file: the loader says how it frames and lights it.
    assert {w.message.file for w in caught} == {str(models / "BoxTextured-GLB" / "BoxTextured.glb")}
    assert len(scene.warnings) == len(caught)
    assert scene.render_settings()["integrator"] == "path"
    image = glint.render(scene, width=32, height=24, spp=2)
    assert image.shape == (24, 32, 3) and np.isfinite(image).all()
    assert image.std() > 0.01, "a blank render"


def test_a_gltf_with_an_external_buffer_renders_as_the_same_box_in_a_glb(models):
    gltf = quiet_load(models / "gltf-rs" / "Box.gltf")
    glb = quiet_load(models / "gltf-rs" / "Box.glb")
    settings = dict(width=24, height=18, spp=2, seed=4)
    image = glint.render(gltf, **settings)
    assert image.std() > 0.01, "a blank render"
    assert np.array_equal(bits(image), bits(glint.render(glb, **settings)))


def test_a_gltf_without_its_buffer_raises_a_located_scene_error(models, tmp_path):
    shutil.copy(models / "gltf-rs" / "Box.gltf", tmp_path / "Box.gltf")
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(tmp_path / "Box.gltf")
    error = caught.value
    assert error.file == str(tmp_path / "Box.gltf")
    assert error.line >= 1 and error.column >= 1
    assert "Box0.bin" in error.message
    assert str(error).startswith(f"{error.file}:{error.line}:{error.column}: ")


def coverage(scene: glint.Scene) -> int:
    """How many pixels of a 32 x 32 depth render see the model."""
    depth = glint.render(scene, width=32, height=32, integrator="depth")
    return int((depth[:, :, 0] > 0).sum())


def test_scene_chooses_one_of_the_files_scenes(models):
    path = models / "MultipleScenes" / "MultipleScenes.gltf"
    # Scene 1 (the file's default) is a square, scene 0 a triangle, half of it; both are
    # framed alike (the same bounds), so the triangle covers about half the pixels.
    square, chosen = coverage(quiet_load(path)), coverage(quiet_load(path, scene=1))
    triangle = coverage(quiet_load(path, scene=0))
    assert square == chosen
    assert 0.35 < triangle / square < 0.65, (triangle, square)
    with pytest.raises(glint.SceneError, match="there is no scene 2"):
        glint.load_scene(path, scene=2)
    with pytest.raises(TypeError, match="index"):
        glint.load_scene(path, scene="0")


def test_a_camera_the_model_lacks_raises_a_located_scene_error(models):
    path = models / "gltf-rs" / "Box.gltf"
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(path, camera="no such camera")
    error = caught.value
    assert error.file == str(path)
    assert error.line >= 1 and error.column >= 1
    assert "no such camera" in error.message and "names no camera" in error.message
    assert str(error).startswith(f"{path}:{error.line}:{error.column}: ")


def test_load_scene_text_reads_a_gltf_and_finds_its_buffer_in_base_dir(models):
    folder = models / "gltf-rs"
    text = (folder / "Box.gltf").read_text()
    from_file = glint.render(quiet_load(folder / "Box.gltf"), width=16, height=12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", glint.SceneWarning)
        named = glint.load_scene_text(text, base_dir=folder, name="Box.gltf")
        typed = glint.load_scene_text(text, format="gltf", base_dir=folder)
    assert typed.name == str(folder / "<text>.gltf")
    for scene in (named, typed):
        assert np.array_equal(bits(glint.render(scene, width=16, height=12)), bits(from_file))
    with pytest.raises(glint.SceneError, match="Box0.bin"):
        glint.load_scene_text(text, format="gltf")  # the current directory has no Box0.bin


def uniform_environment(path: Path) -> Path:
    glint.write_image(path, np.full((4, 8, 3), 0.5, np.float32))
    return path


def test_env_lights_a_model_as_the_clis_env(models, cli, tmp_path):
    env = uniform_environment(tmp_path / "sky.exr")
    model = models / "BoxTextured-GLB" / "BoxTextured.glb"
    scene = quiet_load(model, env=env, env_strength=2.0)
    image = glint.render(scene, width=24, height=18, spp=4, seed=2)
    # A corner misses the box: it sees the environment, 0.5 x 2.
    assert np.allclose(image[0, 0], 1.0)
    output = tmp_path / "cli.exr"
    command = [str(cli), "render", str(model), "-o", str(output), "-w", "24", "-h", "18"]
    command += ["-r", "4", "--seed", "2", "--env", str(env), "--env-strength", "2", "-n", "2"]
    run = subprocess.run(command, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    channels = read_exr(output)
    expected = np.stack([channels[c] for c in ("R", "G", "B")], axis=2)
    assert np.array_equal(bits(image), bits(expected))
    # An unpickled scene is loaded again with the same model options and environment.
    again = pickle.loads(pickle.dumps(scene))
    assert np.array_equal(
        bits(glint.render(again, width=24, height=18, spp=4, seed=2)), bits(image)
    )


def test_env_arguments_are_checked(models, tmp_path):
    model = models / "gltf-rs" / "Box.glb"
    with pytest.raises(ValueError, match="env_strength"):
        glint.load_scene(model, env_strength=2.0)
    env = uniform_environment(tmp_path / "sky.exr")
    with pytest.raises(ValueError, match="env_strength"):
        glint.load_scene(model, env=env, env_strength=-1.0)
    with pytest.raises(glint.SceneError, match="environment map") as caught:
        glint.load_scene(model, env=tmp_path / "none.exr")
    assert caught.value.file == str(tmp_path / "none.exr")
