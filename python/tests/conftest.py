"""Shared fixtures: the repository's example scene, the `glint` CLI, an EXR reader."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
THREE_SPHERES = REPO / "scenes" / "three_spheres.xml"

# The EXR channels the CLI writes (Blender's multilayer pass names; README: feature layers),
# by the layer `glint.render(..., features=True)` returns them under.
EXR_CHANNELS = {
    "beauty": ["R", "G", "B"],
    "albedo": ["Denoising Albedo.R", "Denoising Albedo.G", "Denoising Albedo.B"],
    "normal": ["Denoising Normal.X", "Denoising Normal.Y", "Denoising Normal.Z"],
}
EXR_DEPTH = "Depth.Z"


def _missing(what: str) -> None:
    """Under CI a missing tool is a failure, elsewhere a skip that says so."""
    if os.environ.get("CI"):
        pytest.fail(f"{what} is missing (CI is set, so this fails instead of skipping)")
    pytest.skip(f"SKIPPED: {what} is missing")


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `glint` binary: $GLINT_CLI, else the workspace's release or debug build."""
    candidates = [os.environ.get("GLINT_CLI")] if os.environ.get("GLINT_CLI") else []
    candidates += [str(REPO / "target" / p / "glint") for p in ("release", "debug")]
    candidates.append(shutil.which("glint") or "")
    for candidate in candidates:
        if candidate and Path(candidate).is_file():
            return Path(candidate)
    _missing("the glint CLI (cargo build -p glint, or set GLINT_CLI)")
    raise AssertionError("unreachable")


def read_exr(path: Path) -> dict[str, np.ndarray]:
    """Every channel of an EXR file by name, each an (H, W) array."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as exr:
        return {name: np.array(channel.pixels) for name, channel in exr.channels().items()}
