# Type stubs for the native module `glint._glint` (src/lib.rs). Use it through `glint`.

from collections.abc import Callable
from typing import Any, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "SceneError",
    "SceneWarning",
    "Scene",
    "load_scene",
    "load_scene_text",
    "_restore",
    "render",
    "write_image",
    "denoise",
    "DenoiserUnavailable",
    "GpuUnavailable",
    "TILE_SIZE",
    "MAX_SIDE",
    "MAX_DEPTH",
    "MAX_THREADS",
    "MAX_SPP",
]

TILE_SIZE: int
MAX_SIDE: int
MAX_DEPTH: int
MAX_THREADS: int
MAX_SPP: int

class SceneError(ValueError):
    file: str
    line: int
    column: int
    message: str

class DenoiserUnavailable(RuntimeError): ...
class GpuUnavailable(RuntimeError): ...

class SceneWarning(UserWarning):
    file: str
    line: int
    column: int
    message: str

@final
class Scene:
    @property
    def name(self) -> str: ...
    @property
    def warnings(self) -> list[SceneWarning]: ...
    def render_settings(
        self,
        width: int | None = None,
        height: int | None = None,
        spp: int | None = None,
        integrator: str | None = None,
        max_depth: int | None = None,
    ) -> dict[str, Any]: ...
    def __reduce__(
        self,
    ) -> tuple[
        Any,
        tuple[
            str,
            str | None,
            tuple[float, float, float] | None,
            list[tuple[str, str]],
            int | None,
            str | None,
            str | None,
            float,
        ],
    ]: ...

_RGB = tuple[float, float, float]
_Defines = list[tuple[str, str]]

def load_scene(
    path: str,
    background: _RGB | None = None,
    defines: _Defines | None = None,
    scene: int | None = None,
    camera: str | None = None,
    env: str | None = None,
    env_strength: float = 1.0,
) -> Scene: ...
def load_scene_text(
    text: str,
    path: str,
    background: _RGB | None = None,
    defines: _Defines | None = None,
    scene: int | None = None,
    camera: str | None = None,
    env: str | None = None,
    env_strength: float = 1.0,
) -> Scene: ...
def _restore(
    path: str,
    text: str | None = None,
    background: _RGB | None = None,
    defines: _Defines | None = None,
    scene: int | None = None,
    camera: str | None = None,
    env: str | None = None,
    env_strength: float = 1.0,
) -> Scene: ...
def render(
    scene: Scene,
    width: int,
    height: int,
    spp: int,
    integrator: str,
    seed: int,
    threads: int | None,
    max_depth: int | None,
    aspect: float | None,
    bounds: tuple[int, int, int, int] | None,
    features: bool,
    progress: Callable[[float], object] | None,
    device: str = "cpu",
    background: _RGB | None = None,
    depth: float | None = None,
    aperture: float | None = None,
) -> npt.NDArray[np.float32] | dict[str, npt.NDArray[np.float32]]: ...
def write_image(
    path: str,
    beauty: npt.NDArray[np.float32],
    albedo: npt.NDArray[np.float32] | None = None,
    normal: npt.NDArray[np.float32] | None = None,
    depth: npt.NDArray[np.float32] | None = None,
    integrator: str | None = None,
    exposure: float | None = None,
    tonemap: str | None = None,
    transfer: str | None = None,
) -> None: ...
def denoise(
    color: npt.NDArray[np.float32],
    albedo: npt.NDArray[np.float32] | None,
    normal: npt.NDArray[np.float32] | None,
    prefilter: bool,
    pyoidn_library: str | None,
) -> npt.NDArray[np.float32]: ...
