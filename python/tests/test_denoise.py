"""glint.denoise: OIDN on numpy arrays, its argument errors, and the error without OIDN."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import _missing

import glint


def _denoise_or_skip(*args, **kwargs) -> np.ndarray:
    try:
        return glint.denoise(*args, **kwargs)
    except glint.DenoiserUnavailable as error:
        _missing(f"Open Image Denoise ({error})")
        raise


def _smooth_and_noisy() -> tuple[np.ndarray, np.ndarray]:
    height, width = 48, 64
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    clean = np.stack([0.2 + 0.5 * x / width, 0.3 + 0.4 * y / height, 0.5 + 0 * x], axis=-1)
    noise = np.random.default_rng(7).uniform(-0.25, 0.25, clean.shape)
    return clean.astype(np.float32), np.maximum(clean + noise, 0).astype(np.float32)


def test_noise_on_a_smooth_image_drops_tenfold():
    # OIDN 2.5 cuts this MSE about 60 times; the input handed back would be 1.
    clean, noisy = _smooth_and_noisy()
    before = noisy.copy()
    denoised = _denoise_or_skip(noisy)
    assert denoised.dtype == np.float32 and denoised.shape == noisy.shape
    assert np.array_equal(noisy, before), "the input was changed"
    assert np.mean((noisy - clean) ** 2) > 10 * np.mean((denoised - clean) ** 2)


def test_a_render_denoised_with_its_layers():
    scene = glint.scene_from_dict(glint.BALL)
    layers = glint.render(scene, width=40, height=30, spp=4, integrator="path", features=True)
    for prefilter in (True, False):
        denoised = _denoise_or_skip(
            layers["beauty"], layers["albedo"], layers["normal"], prefilter=prefilter
        )
        assert denoised.shape == (30, 40, 3)
        assert np.isfinite(denoised).all()
        assert not np.array_equal(denoised, layers["beauty"])


def test_argument_errors_name_the_argument():
    color = np.zeros((8, 6, 3), np.float32)
    with pytest.raises(TypeError, match="color must be a float32 array, not float64"):
        glint.denoise(color.astype(np.float64))
    with pytest.raises(TypeError, match="color must be a numpy array"):
        glint.denoise([[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"albedo has shape \(8, 5, 3\)"):
        glint.denoise(color, color[:, :5])
    with pytest.raises(ValueError, match=r"normal must have shape \(H, W, 3\)"):
        glint.denoise(color, color, color[..., 0])
    # Checked before OIDN is looked for, so these need no OIDN.
    with pytest.raises(ValueError, match="normal: OIDN takes a normal layer only with"):
        glint.denoise(color, None, color)
    nan = color.copy()
    nan[2, 3, 1] = np.nan
    with pytest.raises(ValueError, match=r"albedo: pixel \(3, 2\) is not finite"):
        glint.denoise(color, nan)


def test_without_oidn_the_error_says_what_to_install():
    # In a fresh interpreter: this one may have loaded OIDN already, and keeps it.
    code = (
        "import glint, numpy as np\n"
        "try:\n"
        "    glint.denoise(np.zeros((4, 4, 3), np.float32))\n"
        "except RuntimeError as error:\n"
        "    print(type(error).__name__, error)\n"
    )
    missing = "/nonexistent/libOpenImageDenoise.so.2"
    env = dict(os.environ, GLINT_OIDN_LIB=missing)
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert result.stdout.startswith("DenoiserUnavailable"), result.stdout + result.stderr
    assert missing in result.stdout and "pip install pyoidn" in result.stdout
