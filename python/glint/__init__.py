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
import os
import sys
import warnings
from collections.abc import Mapping
from typing import Callable, Union

import numpy as np

from glint import _glint
from glint._glint import TILE_SIZE, DenoiserUnavailable, Scene, SceneError, SceneWarning

__all__ = [
    "BALL",
    "INTEGRATORS",
    "RGB",
    "TILE_SIZE",
    "DenoiserUnavailable",
    "Scene",
    "SceneError",
    "SceneWarning",
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
        os.fspath(path),
        _rgb(background),
        _defines(defines),
        *_model(scene, camera, env),
        env_strength,
    )
    _issue_warnings(loaded)
    return loaded


def _model(
    scene: int | None, camera: str | int | None, env: PathLike | None
) -> tuple[int | None, str | None, str | None]:
    """``scene``, ``camera`` and ``env`` as the native module takes them."""
    if scene is not None and (isinstance(scene, bool) or not isinstance(scene, int)):
        raise TypeError(f"scene must be an index (int), not {type(scene).__name__}")
    if camera is not None and (isinstance(camera, bool) or not isinstance(camera, (str, int))):
        raise TypeError(f"camera must be a name (str) or an index (int), not {camera!r}")
    return (
        scene,
        None if camera is None else str(camera),
        None if env is None else os.fspath(env),
    )


def _defines(defines: Mapping[str, str] | None) -> list[tuple[str, str]] | None:
    if defines is None:
        return None
    if not isinstance(defines, Mapping):
        raise TypeError(f"defines must be a dict of str to str, not {type(defines).__name__}")
    for name, value in defines.items():
        if not (isinstance(name, str) and isinstance(value, str)):
            raise TypeError(f"defines must map str to str, not {name!r} to {value!r}")
    return list(defines.items())


def _rgb(background: RGB | None) -> RGB | None:
    if background is None:
        return None
    r, g, b = (float(c) for c in background)
    return (r, g, b)


def _text_path(format: str, base_dir: PathLike | None, name: str | None) -> str:
    if format not in ("json", "xml", "gltf"):
        raise ValueError(f"format must be 'json', 'xml' or 'gltf', not {format!r}")
    name = name if name is not None else f"<text>.{format}"
    return name if base_dir is None else os.path.join(os.fspath(base_dir), name)


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
        env_strength,
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
    text = json.dumps(scene, indent=2)
    path = _text_path("json", base_dir, name)
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
) -> np.ndarray | dict[str, np.ndarray]:
    """Renders ``scene`` into a linear float32 array of shape ``(height, width, 3)``.

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
    settled = scene.render_settings(
        width=width, height=height, spp=spp, integrator=integrator, max_depth=max_depth
    )
    bounds = None if crop is None else _bounds(crop, settled["width"], settled["height"])
    return _glint.render(
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
    )


def tiles(width: int, height: int, size: int = 4 * TILE_SIZE) -> list[Crop]:
    """The crops that cover a ``width`` x ``height`` image in ``size`` x ``size`` tiles, row by
    row: pieces of one frame to render apart (see :func:`render`'s ``crop``).

    >>> glint.tiles(100, 50, size=64)
    [(slice(0, 50, None), slice(0, 64, None)), (slice(0, 50, None), slice(64, 100, None))]
    """
    if size < 1:
        raise ValueError(f"the tile size must be at least 1, not {size}")
    return [
        (slice(y, min(y + size, height)), slice(x, min(x + size, width)))
        for y in range(0, height, size)
        for x in range(0, width, size)
    ]


def _float32(name: str, array: object, dimensions: int) -> np.ndarray:
    array = np.ascontiguousarray(array, dtype=np.float32)
    if array.ndim != dimensions:
        shape = "(H, W, 3)" if dimensions == 3 else "(H, W)"
        raise ValueError(f"{name} must have shape {shape}, not {array.shape}")
    return array


def write_image(path: PathLike, image: np.ndarray | Mapping[str, np.ndarray]) -> None:
    """Writes an image as the CLI does, by the file name's extension: ``.png`` (8-bit, the
    course's conversion: clamp, floor(c * 255), no gamma) or ``.exr`` (linear float32).

    ``image`` is an ``(H, W, 3)`` array, or :func:`render`'s dict with ``features=True``,
    whose feature layers go into the EXR as the CLI writes them (``Denoising Albedo.R`` ...,
    ``Denoising Normal.X`` ..., ``Depth.Z``). The file is written whole or not at all.

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> glint.write_image(folder / "ball.png", glint.render(glint.scene_from_dict(BALL)))
    >>> (folder / "ball.png").read_bytes()[1:4]
    b'PNG'
    """
    path = os.fspath(path)
    if isinstance(image, Mapping):
        layers = [(key, image.get(key)) for key in ("albedo", "normal", "depth")]
        _glint.write_image(
            path,
            _float32("beauty", image["beauty"], 3),
            *(
                None if layer is None else _float32(key, layer, 2 if key == "depth" else 3)
                for key, layer in layers
            ),
        )
    else:
        _glint.write_image(path, _float32("the image", image, 3))


def to_srgb8(array: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """Linear RGB to displayable 8-bit sRGB: scaled by 2**exposure, clamped to [0, 1], the sRGB
    transfer curve, rounded. NaN becomes 0. For matplotlib's ``imshow`` or ``PIL.Image``.

    (The course's PNGs, which :func:`write_image` writes, have no gamma; this is for looking.)

    >>> glint.to_srgb8(np.array([0.0, 0.18, 1.0, 7.0], np.float32)).tolist()
    [0, 118, 255, 255]
    >>> glint.to_srgb8(np.array([0.09], np.float32), exposure=1).tolist()
    [118]
    """
    linear = np.asarray(array, dtype=np.float32) * np.float32(2.0**exposure)
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
    return _glint.denoise(color, layers[0], layers[1], bool(prefilter), _pyoidn_library())
