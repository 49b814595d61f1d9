"""`glint.render`'s device, background and depth of field: the CLI's `--device`,
`--background`, `-d` and `--aperture`."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import THREE_SPHERES, _missing, read_exr

import glint


def bits(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


SETTINGS = dict(width=36, height=24, spp=4, seed=5)


@pytest.mark.parametrize(
    "integrator, flags, kwargs",
    [
        ("course", ["--background", "0.5,0.25,0"], dict(background=(0.5, 0.25, 0))),
        ("path", ["-d", "3"], dict(depth=3)),
        ("path", ["-d", "2.5", "--aperture", "0.2"], dict(depth=2.5, aperture=0.2)),
        (
            "course",
            ["-d", "4", "--aperture", "0.1", "--background", "1,1,1"],
            dict(depth=4, aperture=0.1, background=(1, 1, 1)),
        ),
        ("path", ["-d", "0"], dict(depth=0)),
    ],
)
def test_render_options_give_the_clis_pixels(cli, tmp_path, integrator, flags, kwargs):
    output = tmp_path / "cli.exr"
    command = [str(cli), "render", str(THREE_SPHERES), "-o", str(output), "-n", "2"]
    command += ["-w", "36", "-h", "24", "-r", "4", "--seed", "5", "--integrator", integrator]
    subprocess.run(command + flags, check=True, capture_output=True)
    written = read_exr(output)
    from_cli = np.stack([written[c] for c in "RGB"], axis=2)
    scene = glint.load_scene(THREE_SPHERES)
    image = glint.render(scene, integrator=integrator, **SETTINGS, **kwargs)
    assert np.array_equal(bits(image), bits(from_cli))


def test_the_options_change_the_image_and_leave_the_scene_as_it_was():
    scene = glint.load_scene(THREE_SPHERES)
    plain = glint.render(scene, integrator="path", **SETTINGS)
    blurred = glint.render(scene, integrator="path", depth=1, aperture=0.3, **SETTINGS)
    white = glint.render(scene, background=(1, 1, 1), **SETTINGS)
    assert not np.array_equal(plain, blurred)
    assert white[0, 0].tolist() == [1.0, 1.0, 1.0]
    # Not kept on the scene: the next plain render is the first one.
    assert np.array_equal(bits(glint.render(scene, integrator="path", **SETTINGS)), bits(plain))
    assert glint.render(scene, **SETTINGS)[0, 0].tolist() != [1.0, 1.0, 1.0]


def test_the_gpu_refuses_what_it_does_not_do_before_opening_a_device():
    scene = glint.load_scene(THREE_SPHERES)
    with pytest.raises(ValueError, match='integrator="path"|path tracer'):
        glint.render(scene, device="gpu", integrator="course", width=8, height=8)


def test_without_a_gpu_adapter_device_gpu_raises_gpu_unavailable(tmp_path):
    # The Vulkan loader finds no driver when pointed at a manifest that does not exist.
    missing = str(tmp_path / "no-driver.json")
    env = {**os.environ, "VK_ICD_FILENAMES": missing, "VK_DRIVER_FILES": missing}
    script = (
        "import glint\n"
        f"scene = glint.load_scene({str(THREE_SPHERES)!r})\n"
        "try:\n"
        "    glint.render(scene, device='gpu', integrator='path', width=8, height=8)\n"
        "except glint.GpuUnavailable as error:\n"
        "    assert isinstance(error, RuntimeError)\n"
        "    print('refused:', error)\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], env=env, cwd=tmp_path, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("refused: no GPU adapter found")
    assert 'device="cpu"' in result.stdout


def test_the_gpu_renders_the_path_tracer():
    scene = glint.load_scene(THREE_SPHERES)
    settings = dict(width=24, height=16, spp=16, integrator="path")
    try:
        gpu = glint.render(scene, device="gpu", **settings)
    except glint.GpuUnavailable as error:
        _missing(f"a GPU adapter (Vulkan; lavapipe will do): {error}")
        return
    cpu = glint.render(scene, **settings)
    assert gpu.shape == cpu.shape == (16, 24, 3)
    assert isinstance(gpu, glint.Image) and gpu.integrator == "path"
    assert np.isfinite(gpu).all()
    # Other random numbers, the same image in distribution: the image means agree within 5%.
    assert abs(gpu.mean() - cpu.mean()) < 0.05 * cpu.mean()
    # The thin lens too (the GPU's own test holds it to the CPU pixel by pixel in distribution).
    lens = dict(settings, depth=4.0, aperture=0.3)
    gpu_lens = glint.render(scene, device="gpu", **lens)
    cpu_lens = glint.render(scene, **lens)
    assert np.isfinite(gpu_lens).all()
    assert abs(gpu_lens.mean() - cpu_lens.mean()) < 0.05 * cpu_lens.mean()
    assert not np.allclose(gpu_lens, gpu)
