"""The same image as the CLI: `glint.render` returns exactly the pixels `glint -o x.exr` writes,
and the same messages for bad scenes."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from conftest import EXR_CHANNELS, EXR_DEPTH, THREE_SPHERES, read_exr

import glint


def bits(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


@pytest.mark.parametrize(
    "integrator, spp, seed, extra",
    [
        ("course", 9, 0, {}),
        ("course", 4, 0, {"background": (0.2, 0.2, 0.2)}),
        ("course", 4, 7, {"max_depth": 2}),
        ("path", 8, 3, {}),
        ("path", 5, 12, {"aspect": 1.25, "max_depth": 3}),
        ("normals", 1, 0, {}),
    ],
)
def test_render_returns_the_cli_exr_pixels(cli, tmp_path, integrator, spp, seed, extra):
    width, height = 45, 30
    output = tmp_path / "cli.exr"
    command = [str(cli), "render", str(THREE_SPHERES), "-o", str(output), "-w", str(width)]
    command += ["-h", str(height), "-r", str(spp), "--seed", str(seed), "--integrator", integrator]
    command += ["-n", "2"]
    if "max_depth" in extra:
        command += ["-k", str(extra["max_depth"])]
    if "aspect" in extra:
        command += ["-a", str(extra["aspect"])]
    background = extra.pop("background", None)
    if background is not None:
        command += ["--background", ",".join(str(c) for c in background)]
    subprocess.run(command, check=True, capture_output=True)
    written = read_exr(output)

    scene = glint.load_scene(THREE_SPHERES, background=background)
    layers = glint.render(
        scene,
        width=width,
        height=height,
        spp=spp,
        integrator=integrator,
        seed=seed,
        features=True,  # the CLI computes the feature layers for an EXR
        **extra,
    )
    for layer, names in EXR_CHANNELS.items():
        from_cli = np.stack([written[name] for name in names], axis=2)
        assert np.array_equal(bits(layers[layer]), bits(from_cli)), layer
    assert np.array_equal(bits(layers["depth"]), bits(written[EXR_DEPTH]))
    # And the beauty alone is the same without the feature layers.
    beauty = glint.render(
        scene,
        width=width,
        height=height,
        spp=spp,
        integrator=integrator,
        seed=seed,
        **extra,
    )
    assert np.array_equal(bits(beauty), bits(layers["beauty"]))


@pytest.mark.parametrize(
    "text",
    [
        '<scene>\n  <shape type="sphere">\n    <radius>-1</radius>\n  </shape>\n</scene>\n',
        '{"scene": {\n  "camera": [{"_type": "perspective", "position": "0 0"}]}}\n',
        "<scene><camera></scene>\n",
    ],
)
def test_scene_errors_say_what_the_cli_says(cli, tmp_path, text):
    path = tmp_path / ("bad.xml" if text.startswith("<") else "bad.json")
    path.write_text(text)
    result = subprocess.run(
        [str(cli), "render", str(path), "-o", str(tmp_path / "out.png")],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2
    with pytest.raises(glint.SceneError) as caught:
        glint.load_scene(path)
    assert result.stderr == f"error: {caught.value}\n"


def test_scene_warnings_say_what_the_cli_says(cli, tmp_path):
    path = tmp_path / "odd.xml"
    text = THREE_SPHERES.read_text().replace("<scene ", '<scene colour="red" ', 1)
    path.write_text(text.replace("<focalLength>", "<focalLenght>1</focalLenght><focalLength>"))
    result = subprocess.run(
        [str(cli), "render", str(path), "-o", str(tmp_path / "out.png"), "-w", "4", "-h", "4"],
        capture_output=True,
        text=True,
        check=True,
    )
    with pytest.warns(glint.SceneWarning) as caught:
        glint.load_scene(path)
    shown = [f"warning: {w.message}" for w in caught]
    assert len(shown) == 2
    assert result.stderr.startswith("\n".join(shown) + "\n")
