"""Glint from Python: load the course's ray-tracing scenes, Mitsuba 3's, or glTF 2.0 models,
and render them into numpy arrays.

The same renderer as the ``glint`` command: for the same scene, settings and seed,
:func:`render` returns exactly the pixels the CLI writes to an EXR file.

>>> import glint, numpy as np
>>> scene = glint.scene_from_dict(BALL)
>>> image = glint.render(scene, width=32, height=24, spp=4)
>>> image.shape, image.dtype
((24, 32, 3), dtype('float32'))
>>> bool(image[12, 16, 0] > image[12, 16, 1])  # the ball in the middle is red
True
>>> glint.to_srgb8(image).dtype
dtype('uint8')

Tiles of one frame can be rendered anywhere (other processes, other machines, Dask tasks) and
put together into the same image, bit for bit:

>>> full = np.zeros((24, 32, 3), np.float32)
>>> for crop in glint.tiles(32, 24, size=16):
...     full[crop] = glint.render(scene, width=32, height=24, spp=4, crop=crop)
>>> np.array_equal(full, image)
True

(``BALL`` is a small scene in the course's JSON, as a dict: ``glint.BALL``.)
"""

from __future__ import annotations

import importlib.util
import json
import math
import numbers
import os
import sys
import warnings
from collections.abc import Mapping
from typing import Any, Callable, Union

import numpy as np

try:
    from glint import _glint
except ImportError as error:
    # Run from inside python/, `import glint` finds this source folder, which has no compiled
    # module, before the installed package; Python then reports a confusing circular import.
    _here = os.path.dirname(os.path.abspath(__file__))
    _compiled = [
        name for name in os.listdir(_here) if name.startswith("_glint") and name != "_glint.pyi"
    ]
    if _compiled or getattr(error, "name", None) not in ("glint._glint", "glint"):
        raise
    raise ImportError(
        f"glint's native module is missing: this `glint` is the source folder {_here}, which "
        "has no compiled `_glint` module (Python looks in the current directory, or the "
        "script's, before the installed packages). "
        "Run Python from another directory to use the installed glint (pip install ./python), "
        "or build the module into this folder with `maturin develop --release` (in python/, "
        "inside a virtual environment)."
    ) from error
from glint._glint import (
    TILE_SIZE,
    DenoiserUnavailable,
    GpuUnavailable,
    Scene,
    SceneError,
    SceneWarning,
)

__all__ = [
    "BALL",
    "INTEGRATORS",
    "RGB",
    "TILE_SIZE",
    "DEVICES",
    "DenoiserUnavailable",
    "GpuUnavailable",
    "Image",
    "Scene",
    "SceneError",
    "SceneWarning",
    "TONEMAPS",
    "TRANSFERS",
    "denoise",
    "load_scene",
    "load_scene_text",
    "render",
    "scene_from_dict",
    "tiles",
    "to_srgb8",
    "write_image",
]

PathLike = Union[str, "os.PathLike[str]"]
Crop = tuple[slice, slice]
RGB = tuple[float, float, float]

#: The integrators :func:`render` knows, as the CLI's ``--integrator`` names them.
INTEGRATORS = ("course", "path", "volpath", "normals", "albedo", "depth")
#: Where :func:`render` runs, as the CLI's ``--device`` names them.
DEVICES = ("cpu", "gpu")
#: The tone curves of :func:`write_image`, as the CLI's ``--tonemap`` names them.
TONEMAPS = ("clamp", "none", "aces", "agx")
#: The transfer functions of :func:`write_image`, as the CLI's ``--transfer`` names them.
TRANSFERS = ("srgb", "linear")

# The CLI's limits (crates/cli/src/args.rs), from the native module.
_MAX_SIDE = _glint.MAX_SIDE
_MAX_DEPTH = _glint.MAX_DEPTH
_MAX_THREADS = _glint.MAX_THREADS
_MAX_SPP = _glint.MAX_SPP
_MAX_SEED = 2**64 - 1
_MAX_EXPOSURE = 64.0


# Argument checks: a wrong type raises TypeError, a wrong value ValueError, each naming the
# argument and what it accepts, as the CLI names its flags.


def _int(name: str, value: Any, low: int, high: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = int(value)
    if high is None and value < low:
        raise ValueError(f"{name} must be at least {low}, got {value}")
    if high is not None and not low <= value <= high:
        raise ValueError(f"{name} must be between {low} and {high}, got {value}")
    return value


def _opt_int(name: str, value: Any, low: int, high: int | None = None) -> int | None:
    return None if value is None else _int(name, value, low, high)


def _real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number, not {type(value).__name__}")
    return float(value)


def _non_negative(name: str, value: Any) -> float:
    number = _real(name, value)
    if not (math.isfinite(number) and number >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return number


def _choice(name: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, one of {', '.join(choices)}, not {value!r}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(choices)}, got {value!r}")
    return value


def _bool(name: str, value: Any) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, not {value!r}")
    return bool(value)


def _path(name: str, value: Any) -> str:
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name} must be a path (str or os.PathLike), not {type(value).__name__}")
    path = os.fspath(value)
    if not isinstance(path, str):
        raise TypeError(f"{name} must be a str path, not {type(path).__name__}")
    return path


def _str(name: str, value: Any) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, not {type(value).__name__}")
    return value


def _exposure(value: Any) -> float:
    exposure = _real("exposure", value)
    if not (math.isfinite(exposure) and abs(exposure) <= _MAX_EXPOSURE):
        raise ValueError(f"exposure must be between -64 and 64 (stops), got {value!r}")
    return exposure


class Image(np.ndarray):
    """A rendered image: :func:`render`'s float32 ``(H, W, 3)`` array, which also says how it
    was made, so that :func:`write_image` writes its PNG as ``glint render`` would.

    It is a numpy array in every other way; slices, copies and arithmetic on it keep
    ``integrator``, and ``np.asarray(image)`` is the plain array.
    """

    #: The integrator that rendered it (one of :data:`INTEGRATORS`), or ``None``.
    integrator: str | None

    def __array_finalize__(self, obj: object) -> None:
        self.integrator = getattr(obj, "integrator", None)

    def __reduce__(self) -> tuple[Any, ...]:
        # numpy pickles the array alone; the integrator goes along with it.
        rebuild, arguments, state = super().__reduce__()  # type: ignore[misc]
        return rebuild, arguments, (state, self.integrator)

    def __setstate__(self, state: Any) -> None:
        array_state, self.integrator = state
        super().__setstate__(array_state)


def _image(array: np.ndarray, integrator: str) -> Image:
    image = array.view(Image)
    image.integrator = integrator
    return image


#: A red ball in front of a grey background, lit by a point light: the course's JSON as a dict.
BALL = {
    "scene": {
        "camera": [
            {
                "_name": "main",
                "_type": "perspective",
                "position": "0 0 3",
                "viewDir": "0 0 -1",
                "focalLength": 1.0,
                "imagePlaneWidth": 1.0,
            }
        ],
        "light": [{"_type": "point", "position": "2 2 3", "intensity": "1 1 1"}],
        "shader": [{"_name": "red", "_type": "Lambertian", "diffuse": "0.8 0.1 0.1"}],
        "shape": [
            {
                "_name": "ball",
                "_type": "sphere",
                "shader": {"_ref": "red"},
                "center": "0 0 0",
                "radius": 1.0,
            }
        ],
        "bgColor": "0.2 0.2 0.2",
    }
}


def _issue_warnings(scene: Scene) -> None:
    # stacklevel 3: the frame that called load_scene & co., not this helper or that function.
    for warning in scene.warnings:
        warnings.warn(warning, stacklevel=3)


def load_scene(
    path: PathLike,
    background: RGB | None = None,
    defines: Mapping[str, str] | None = None,
    scene: int | None = None,
    camera: str | int | None = None,
    env: PathLike | None = None,
    env_strength: float = 1.0,
) -> Scene:
    """Loads a scene file, the course's XML or JSON, a Mitsuba 3 scene or a glTF 2.0 model
    (``.gltf`` or ``.glb``), and builds it for rendering.

    Meshes, textures, environment maps and a ``.gltf``'s buffers and images are found relative
    to the file's directory (Glint reads none from above it).
    ``background=(r, g, b)`` replaces the scene's background, as the CLI's ``--background``
    does (the course's reference renders used ``(0.2, 0.2, 0.2)``). ``defines`` gives a
    Mitsuba scene's parameters, ``{"name": "value"}``, as the CLI's ``-D name=value``: they win
    over the scene's ``<default>`` s (course scenes have none and ignore them). A Mitsuba scene
    brings its own film size, sample count and integrator, which :func:`render` uses wherever
    it is not given them.

    For a glTF model, as the CLI's ``--scene N`` and ``--camera NAME|INDEX``: ``scene`` picks
    one of the file's scenes by index (default: the file's default scene) and ``camera`` a
    camera by its or its node's name, or by index (default: the first camera in the scene; with
    none, one that frames the model). A model brings the path tracer and its camera's image
    size for :func:`render`. Other formats ignore both.

    ``env`` lights the scene with an equirectangular environment map (OpenEXR, Radiance
    ``.hdr`` or an 8-bit image), its radiance times ``env_strength``, as the CLI's ``--env`` and
    ``--env-strength``: it replaces the background, and a glTF model then gets no default sky.
    ``background`` wins over it when both are given, as in the CLI.

    What the loader works around (unknown keys, missing textures...) is issued as a
    :class:`SceneWarning` naming ``file:line:col``; a scene that cannot be loaded raises
    :class:`SceneError` (with ``file``, ``line``, ``column`` and ``message``), a file that
    cannot be read ``OSError`` (``FileNotFoundError``...).

    >>> glint.load_scene("no/such/scene.xml")
    Traceback (most recent call last):
    FileNotFoundError: [Errno 2] No such file or directory: 'no/such/scene.xml'
    """
    loaded = _glint.load_scene(
        _path("path", path),
        _rgb(background),
        _defines(defines),
        *_model(scene, camera, env),
        _non_negative("env_strength", env_strength),
    )
    _issue_warnings(loaded)
    return loaded


def _model(
    scene: int | None, camera: str | int | None, env: PathLike | None
) -> tuple[int | None, str | None, str | None]:
    """``scene``, ``camera`` and ``env`` as the native module takes them."""
    if scene is not None and (isinstance(scene, bool) or not isinstance(scene, numbers.Integral)):
        raise TypeError(f"scene must be an index (int), not {type(scene).__name__}")
    scene = _opt_int("scene", scene, 0)
    if camera is not None and not isinstance(camera, str):
        if isinstance(camera, bool) or not isinstance(camera, numbers.Integral):
            raise TypeError(f"camera must be a name (str) or an index (int), not {camera!r}")
        camera = str(_int("camera", camera, 0))
    return (scene, camera, None if env is None else _path("env", env))


def _defines(defines: Mapping[str, str] | None) -> list[tuple[str, str]] | None:
    if defines is None:
        return None
    if not isinstance(defines, Mapping):
        raise TypeError(f"defines must be a dict of str to str, not {type(defines).__name__}")
    for name, value in defines.items():
        if not (isinstance(name, str) and isinstance(value, str)):
            raise TypeError(f"defines must map str to str, not {name!r} to {value!r}")
    return list(defines.items())


def _rgb(background: RGB | None, name: str = "background") -> RGB | None:
    if background is None:
        return None
    if isinstance(background, (str, bytes)) or not hasattr(background, "__len__"):
        raise TypeError(f"{name} must be three numbers (r, g, b), not {background!r}")
    if len(background) != 3:
        raise ValueError(f"{name} must have three components (r, g, b), got {len(background)}")
    for c in background:
        if isinstance(c, bool) or not isinstance(c, numbers.Real):
            raise TypeError(f"{name} must be three numbers (r, g, b), not {background!r}")
    r, g, b = (float(c) for c in background)
    if not all(math.isfinite(c) and c >= 0 for c in (r, g, b)):
        raise ValueError(f"{name} components must be finite and >= 0, got {tuple(background)!r}")
    return (r, g, b)


def _text_path(format: str, base_dir: PathLike | None, name: str | None) -> str:
    _choice("format", format, ("json", "xml", "gltf"))
    name = f"<text>.{format}" if name is None else _str("name", name)
    return name if base_dir is None else os.path.join(_path("base_dir", base_dir), name)


def load_scene_text(
    text: str,
    format: str = "json",
    base_dir: PathLike | None = None,
    name: str | None = None,
    background: RGB | None = None,
    defines: Mapping[str, str] | None = None,
    scene: int | None = None,
    camera: str | int | None = None,
    env: PathLike | None = None,
    env_strength: float = 1.0,
) -> Scene:
    """Loads a scene from its text, in the course's JSON (``format="json"``), XML (the
    course's or Mitsuba 3's) or a glTF 2.0 model's JSON (``format="gltf"``, or a ``name``
    ending in ``.gltf``).

    Diagnostics name the text ``name`` (default ``<text>.json``, ``<text>.xml`` or
    ``<text>.gltf``) inside ``base_dir``, and assets (a model's ``.bin`` buffers and images
    too) are found relative to ``base_dir`` (default: the current directory). ``background``,
    ``defines``, ``scene``, ``camera``, ``env``, ``env_strength``, warnings and errors as for
    :func:`load_scene`.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     scene = glint.load_scene_text('''<scene bgColor="0 0 1">
    ...       <camera name="main" type="perspective"><position>0 0 3</position>
    ...         <viewDir>0 0 -1</viewDir><focalLength>1</focalLength>
    ...         <imagePlaneWidth>1</imagePlaneWidth></camera>
    ...     </scene>''', format="xml")
    >>> warning = caught[0].message
    >>> type(warning).__name__, warning.file, warning.line, warning.column
    ('SceneWarning', '<text>.xml', 1, 1)
    >>> warning.message
    'the scene has no shapes; the image shows only the background'
    >>> glint.render(scene, width=2, height=2)[0, 0].tolist()  # only the blue background
    [0.0, 0.0, 1.0]
    >>> glint.load_scene_text('{"scene": {"camera": 7}}')
    Traceback (most recent call last):
    glint.SceneError: <text>.json:1:22: ...
    >>> glint.load_scene_text('{"asset": {"version": "2.0"}}', format="gltf", camera="top")
    Traceback (most recent call last):
    glint.SceneError: <text>.gltf:...: ...top...
    """
    text = _str("text", text)
    _choice("format", format, ("json", "xml", "gltf"))
    first = text.lstrip("\ufeff \t\r\n")[:1]
    if (format == "xml" and first in ("{", "[")) or (format in ("json", "gltf") and first == "<"):
        raise ValueError(f"format={format!r}, but the text starts with {first!r}")
    path = _text_path(format, base_dir, name)
    loaded = _glint.load_scene_text(
        text,
        path,
        _rgb(background),
        _defines(defines),
        *_model(scene, camera, env),
        _non_negative("env_strength", env_strength),
    )
    _issue_warnings(loaded)
    return loaded


def scene_from_dict(
    scene: Mapping,
    base_dir: PathLike | None = None,
    name: str = "<dict>.json",
    background: RGB | None = None,
) -> Scene:
    """Loads a scene given as the course's JSON document in Python objects (``{"scene": ...}``).

    The dict is written out as indented JSON, so a diagnostic's line and column point into that
    text, and its message shows the offending line. Diagnostics name it ``name`` inside
    ``base_dir``; assets are found relative to ``base_dir`` (default: the current directory).
    ``background`` as for :func:`load_scene`.

    >>> bad = {"scene": {**BALL["scene"], "bgColor": "0.2 0.2"}}
    >>> glint.scene_from_dict(bad)
    Traceback (most recent call last):
    glint.SceneError: <dict>.json:38:16: expected three numbers ... found `0.2 0.2`
        "bgColor": "0.2 0.2"
                   ^
    """
    if not isinstance(scene, Mapping):
        raise TypeError(
            f"scene must be a dict (the course's JSON document), not {type(scene).__name__}"
        )
    try:
        text = json.dumps(scene, indent=2)
    except (TypeError, ValueError) as error:
        raise TypeError(f"scene must hold JSON values only: {error}") from None
    path = _text_path("json", base_dir, _str("name", name))
    loaded = _glint.load_scene_text(text, path, _rgb(background))
    _issue_warnings(loaded)
    return loaded


def _bounds(crop: Crop, width: int, height: int) -> tuple[int, int, int, int]:
    """``(x0, x1, y0, y1)`` of a numpy-style crop ``(rows, columns)``."""
    if not (isinstance(crop, tuple) and len(crop) == 2 and all(isinstance(s, slice) for s in crop)):
        raise TypeError(
            "crop must be a pair of slices (rows, columns) such as np.s_[0:16, 32:48], "
            f"not {crop!r}"
        )
    (y0, y1, y_step), (x0, x1, x_step) = crop[0].indices(height), crop[1].indices(width)
    if x_step != 1 or y_step != 1:
        raise ValueError(f"crop slices must have step 1, not {crop!r}")
    if x1 <= x0 or y1 <= y0:
        raise ValueError(f"crop {crop!r} is empty in a {width}x{height} image")
    return (x0, x1, y0, y1)


def render(
    scene: Scene,
    width: int | None = None,
    height: int | None = None,
    spp: int | None = None,
    integrator: str | None = None,
    seed: int = 0,
    threads: int | None = None,
    max_depth: int | None = None,
    aspect: float | None = None,
    crop: Crop | None = None,
    features: bool = False,
    progress: Callable[[float], object] | None = None,
    device: str = "cpu",
    background: RGB | None = None,
    depth: float = 0.0,
    aperture: float | None = None,
) -> Image | dict[str, np.ndarray]:
    """Renders ``scene`` into a linear float32 array of shape ``(height, width, 3)``, an
    :class:`Image` that remembers its integrator for :func:`write_image`.

    The arguments are the CLI's: ``spp`` samples per pixel (``-r``; the course's integrators
    take them on an N x N grid, N = floor(sqrt(spp))), ``integrator`` one of
    :data:`INTEGRATORS` (``--integrator``), ``seed`` (``--seed``), ``threads`` (``-n``; default
    all cores), ``max_depth`` (``-k``; default 4 for the course, unbounded for ``path``),
    ``aspect`` (``-a``; default width / height). The same arguments give the same pixels as the
    CLI, on any number of threads.

    Where ``width``, ``height``, ``spp``, ``integrator`` or ``max_depth`` is not given, the
    scene's own choice is used, as the CLI uses it without the flag: a Mitsuba scene's film
    size, sample count, integrator (``path``) and depth; otherwise the course's defaults, 100 x
    100, 1 sample, ``course``. :meth:`Scene.render_settings` says what they come to.

    ``crop`` renders only part of the image, given as numpy indexes it
    (``np.s_[y0:y1, x0:x1]``): ``render(s, crop=c)`` equals ``render(s)[c]``, bit for bit.
    With ``features=True`` the result is a dict: ``beauty``, ``albedo`` and ``normal``
    (``(H, W, 3)``) and ``depth`` (``(H, W)``), the first-hit layers a denoiser takes.

    ``device="gpu"`` runs the path tracer (``integrator="path"`` only) on the GPU with wgpu on
    Vulkan, as the CLI's ``--device gpu``: the same image in distribution, not pixel for
    pixel; :class:`GpuUnavailable` (a ``RuntimeError``) when there is no adapter, and
    ``ValueError`` for what the GPU does not do (other integrators, depth of field).
    ``background=(r, g, b)`` replaces the scene's background for this render (the CLI's
    ``--background``). ``depth`` turns on depth of field, focused at that distance along the
    view direction (the CLI's ``-d``/``--depth``; 0, the default, is the course's pinhole), with
    a lens of radius ``aperture`` in scene units (``--aperture``; default 1/50 of the width the
    image covers at the focus distance). With ``background`` or ``depth`` the scene is read
    again from its source (as when unpickled) and built once for them; the last such scene is
    kept for the next call with the same ones.

    Every argument is checked first: a wrong type raises ``TypeError``, a value out of range
    ``ValueError``, each naming the argument and the CLI's limits (``width`` and ``height`` 1 to
    65535, ``spp`` 1 to 16777216, ``max_depth`` 0 to 100, ``threads`` 1 to 1024).

    Samples that come out NaN or infinite are left out of their pixels, as in the CLI, with a
    ``RuntimeWarning`` saying how many and where the first was.

    The GIL is released while rendering. Ctrl-C raises ``KeyboardInterrupt`` once the tiles
    being rendered are done (when called from the main thread: Python delivers signals only
    there). ``progress``, when given, is called on the calling thread with the fraction done
    (0 to 1, ending with 1.0), at most about ten times a second; an exception it raises stops
    the render and is raised here.

    >>> scene = glint.scene_from_dict(BALL)
    >>> layers = glint.render(scene, width=8, height=8, integrator="path", features=True)
    >>> sorted(layers), layers["depth"].shape
    (['albedo', 'beauty', 'depth', 'normal'], (8, 8))
    >>> seen = []
    >>> corner = glint.render(scene, width=8, height=8, crop=np.s_[0:4, 4:8], progress=seen.append)
    >>> corner.shape, seen[-1]
    ((4, 4, 3), 1.0)
    """
    if not isinstance(scene, Scene):
        raise TypeError(
            "scene must be a glint.Scene (from glint.load_scene, load_scene_text or "
            f"scene_from_dict), not {type(scene).__name__}"
        )
    if integrator is not None:
        _choice("integrator", integrator, INTEGRATORS)
    settled = scene.render_settings(
        width=width, height=height, spp=spp, integrator=integrator, max_depth=max_depth
    )
    seed = _int("seed", seed, 0, _MAX_SEED)
    threads = _opt_int("threads", threads, 1, _MAX_THREADS)
    if aspect is not None:
        aspect = _real("aspect", aspect)
        if not (math.isfinite(aspect) and aspect > 0):
            raise ValueError(f"aspect must be a finite number > 0, got {aspect!r}")
    bounds = None if crop is None else _bounds(crop, settled["width"], settled["height"])
    features = _bool("features", features)
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable (it gets a float), not {progress!r}")
    _choice("device", device, DEVICES)
    depth = _non_negative("depth", depth)
    if aperture is not None:
        aperture = _non_negative("aperture", aperture)
        if depth == 0:
            raise ValueError(
                "aperture needs depth of field: give a focus distance depth greater than 0"
            )
    rendered = _glint.render(
        scene,
        settled["width"],
        settled["height"],
        settled["spp"],
        settled["integrator"],
        seed,
        threads,
        settled["max_depth"],
        aspect,
        bounds,
        features,
        progress,
        device,
        _rgb(background),
        depth or None,
        aperture,
    )
    if isinstance(rendered, dict):
        rendered["beauty"] = _image(rendered["beauty"], settled["integrator"])
        return rendered
    return _image(rendered, settled["integrator"])


def tiles(width: int, height: int, size: int = 4 * TILE_SIZE) -> list[Crop]:
    """The crops that cover a ``width`` x ``height`` image in ``size`` x ``size`` tiles, row by
    row: pieces of one frame to render apart (see :func:`render`'s ``crop``).

    >>> glint.tiles(100, 50, size=64)
    [(slice(0, 50, None), slice(0, 64, None)), (slice(0, 50, None), slice(64, 100, None))]
    """
    width = _int("width", width, 1, _MAX_SIDE)
    height = _int("height", height, 1, _MAX_SIDE)
    size = _int("size", size, 1, _MAX_SIDE)
    return [
        (slice(y, min(y + size, height)), slice(x, min(x + size, width)))
        for y in range(0, height, size)
        for x in range(0, width, size)
    ]


def _float32(name: str, array: object, dimensions: int) -> np.ndarray:
    if not isinstance(array, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not {type(array).__name__}")
    if not (np.issubdtype(array.dtype, np.floating) or np.issubdtype(array.dtype, np.integer)):
        raise TypeError(f"{name} must be an array of numbers, not of {array.dtype}")
    array = np.ascontiguousarray(array, dtype=np.float32)
    if array.ndim != dimensions or (dimensions == 3 and array.shape[2] != 3):
        shape = "(H, W, 3)" if dimensions == 3 else "(H, W)"
        raise ValueError(f"{name} must have shape {shape}, not {array.shape}")
    return array


def write_image(
    path: PathLike,
    image: np.ndarray | Mapping[str, np.ndarray],
    *,
    integrator: str | None = None,
    exposure: float | None = None,
    tonemap: str | None = None,
    transfer: str | None = None,
) -> None:
    """Writes an image as ``glint render`` does, by the file name's extension: ``.png``
    (8-bit) or ``.exr`` (linear float32). The file is written whole or not at all.

    ``image`` is an ``(H, W, 3)`` array, or :func:`render`'s dict with ``features=True``,
    whose feature layers go into the EXR as the CLI writes them (``Denoising Albedo.R`` ...,
    ``Denoising Normal.X`` ..., ``Depth.Z``).

    A PNG's 8-bit values are made as the CLI makes them for the integrator that rendered the
    image: an :class:`Image` from :func:`render` knows it, else give ``integrator=``. The
    course integrator and the ``normals`` and ``depth`` views get the course's conversion
    (clamp, floor(c * 255), no gamma: what the course's reference images are); ``path``,
    ``volpath`` and ``albedo`` the display transform (exposure, tone curve, sRGB). An array
    that does not say, with no ``integrator``, gets the course's conversion.
    ``exposure`` (stops, -64 to 64), ``tonemap`` (one of :data:`TONEMAPS`) and ``transfer``
    (one of :data:`TRANSFERS`) are the CLI's ``--exposure``, ``--tonemap`` and
    ``--transfer``: giving any of them turns on the display transform for any integrator,
    with the defaults 0, ``"clamp"`` and ``"srgb"`` for the others. An EXR keeps linear values:
    there they have no effect, and a ``UserWarning`` says so (the CLI's note).

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> scene = glint.scene_from_dict(BALL)
    >>> glint.write_image(folder / "ball.png", glint.render(scene, integrator="path"))
    >>> (folder / "ball.png").read_bytes()[1:4]
    b'PNG'
    """
    path = _path("path", path)
    beauty = image.get("beauty") if isinstance(image, Mapping) else image
    if integrator is None:
        integrator = getattr(beauty, "integrator", None)
    else:
        integrator = _choice("integrator", integrator, INTEGRATORS)
    if exposure is not None:
        exposure = _exposure(exposure)
    if tonemap is not None:
        tonemap = _choice("tonemap", tonemap, TONEMAPS)
    if transfer is not None:
        transfer = _choice("transfer", transfer, TRANSFERS)
    display = (exposure, tonemap, transfer) != (None, None, None)
    if display and os.path.splitext(path)[1].lower() == ".exr":
        warnings.warn(
            "exposure/tonemap/transfer have no effect on an EXR: it keeps linear values",
            UserWarning,
            stacklevel=2,
        )
    encoding = {
        "integrator": integrator,
        "exposure": exposure,
        "tonemap": tonemap,
        "transfer": transfer,
    }
    if isinstance(image, Mapping):
        if "beauty" not in image:
            raise ValueError(f"image has no 'beauty' layer: it has {sorted(image)}")
        layers = [(key, image.get(key)) for key in ("albedo", "normal", "depth")]
        _glint.write_image(
            path,
            _float32("beauty", image["beauty"], 3),
            *(
                None if layer is None else _float32(key, layer, 2 if key == "depth" else 3)
                for key, layer in layers
            ),
            **encoding,
        )
    elif isinstance(image, np.ndarray):
        _glint.write_image(path, _float32("image", image, 3), **encoding)
    else:
        raise TypeError(
            "image must be a numpy array (H, W, 3) or render()'s dict of layers, "
            f"not {type(image).__name__}"
        )


def to_srgb8(array: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """Linear RGB to displayable 8-bit sRGB: scaled by 2**exposure, clamped to [0, 1], the sRGB
    transfer curve, rounded. NaN becomes 0. For matplotlib's ``imshow`` or ``PIL.Image``.

    (:func:`write_image` writes the course integrator's PNGs without gamma, as the course does,
    and the path tracer's with it; this is for looking.)

    >>> glint.to_srgb8(np.array([0.0, 0.18, 1.0, 7.0], np.float32)).tolist()
    [0, 118, 255, 255]
    >>> glint.to_srgb8(np.array([0.09], np.float32), exposure=1).tolist()
    [118]
    """
    linear = np.asarray(array, dtype=np.float32) * np.float32(2.0 ** _exposure(exposure))
    linear = np.nan_to_num(np.clip(linear, 0.0, 1.0), nan=0.0)
    encoded = np.where(
        linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1.0 / 2.4) - 0.055
    )
    return np.round(encoded * 255.0).astype(np.uint8)


def _rgb32(name: str, array: object) -> np.ndarray:
    """``array`` itself when it is a float32 ``(H, W, 3)`` array; otherwise an error naming it."""
    if not isinstance(array, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not {type(array).__name__}")
    if array.dtype != np.float32:
        raise TypeError(f"{name} must be a float32 array, not {array.dtype}")
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{name} must have shape (H, W, 3), not {array.shape}")
    return array


def _pyoidn_library() -> str | None:
    """The OIDN library in the ``pyoidn`` package this interpreter would import, if any; found
    without importing it."""
    spec = importlib.util.find_spec("pyoidn")
    if spec is None or not spec.submodule_search_locations:
        return None
    folder, name = {
        "win32": ("bin", "OpenImageDenoise.dll"),
        "darwin": ("lib", "libOpenImageDenoise.2.dylib"),
    }.get(sys.platform, ("lib", "libOpenImageDenoise.so.2"))
    library = os.path.join(spec.submodule_search_locations[0], "oidn", folder, name)
    return library if os.path.isfile(library) else None


def denoise(
    color: np.ndarray,
    albedo: np.ndarray | None = None,
    normal: np.ndarray | None = None,
    *,
    prefilter: bool = True,
) -> np.ndarray:
    """Denoises an image with Intel's Open Image Denoise 2 (OIDN), as ``glint denoise`` does,
    and returns a new ``(H, W, 3)`` float32 array; the inputs are left as they are.

    ``color`` is linear radiance (HDR), an ``(H, W, 3)`` float32 array, such as
    :func:`render`'s image or the ``"beauty"`` of its dict with ``features=True``. ``albedo``
    (reflectance, in [0, 1]) and ``normal`` (components in [-1, 1]) are that dict's layers,
    the same shape, OIDN's auxiliary images; a normal layer needs the albedo layer too. They
    average noisy first hits, so by default each is denoised first and the colour then with
    OIDN's ``cleanAux``, as OIDN recommends for noisy auxiliary images; ``prefilter=False``
    gives them to OIDN as they are.

    OIDN is found where the CLI looks (``GLINT_OIDN_LIB``, the system's loader, the ``pyoidn``
    package of ``python3``) and in this interpreter's ``pyoidn``; without it
    :class:`DenoiserUnavailable` (a ``RuntimeError``) says what was tried and to
    ``pip install pyoidn``. An argument of the wrong type or dtype raises ``TypeError``, of the
    wrong shape or with non-finite values ``ValueError``, naming the argument::

        layers = glint.render(scene, spp=16, integrator="path", features=True)
        clean = glint.denoise(layers["beauty"], layers["albedo"], layers["normal"])
    """
    color = _rgb32("color", color)
    layers = []
    for name, layer in (("albedo", albedo), ("normal", normal)):
        if layer is not None:
            layer = _rgb32(name, layer)
            if layer.shape != color.shape:
                raise ValueError(f"{name} has shape {layer.shape}, but color has {color.shape}")
        layers.append(layer)
    prefilter = _bool("prefilter", prefilter)
    denoised = _glint.denoise(color, layers[0], layers[1], prefilter, _pyoidn_library())
    integrator = getattr(color, "integrator", None)
    return denoised if integrator is None else _image(denoised, integrator)
