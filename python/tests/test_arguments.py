"""Every public function checks its arguments: a wrong value raises ValueError naming the
argument and what it accepts (the CLI's limits), a wrong type TypeError naming the argument."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from conftest import THREE_SPHERES

import glint

BALL = glint.scene_from_dict(glint.BALL)
IMAGE = np.zeros((4, 4, 3), np.float32)


def render(**kwargs):
    return glint.render(BALL, **{"width": 4, "height": 4, **kwargs})


CASES = [
    # glint.render: each kind of argument.
    (render, dict(width=-5), ValueError, "width must be between 1 and 65535, got -5"),
    (render, dict(width=0), ValueError, "width must be between 1 and 65535, got 0"),
    (render, dict(height=70000), ValueError, "height must be between 1 and 65535, got 70000"),
    (render, dict(width=2**70), ValueError, "width must be between 1 and 65535, got 1180"),
    (render, dict(width=4.0), TypeError, "width must be an int, not float"),
    (render, dict(height="4"), TypeError, "height must be an int, not str"),
    (render, dict(width=True), TypeError, "width must be an int, not bool"),
    (render, dict(spp=-1), ValueError, "spp must be between 1 and 16777216, got -1"),
    (render, dict(spp=None, max_depth=101), ValueError, "max_depth must be between 0 and 100"),
    (render, dict(max_depth=-1), ValueError, "max_depth must be between 0 and 100, got -1"),
    (render, dict(seed=-1), ValueError, "seed must be between 0 and 18446744073709551615"),
    (render, dict(seed=1.5), TypeError, "seed must be an int"),
    (render, dict(threads=0), ValueError, "threads must be between 1 and 1024, got 0"),
    (render, dict(threads="2"), TypeError, "threads must be an int"),
    (render, dict(aspect=-1.0), ValueError, "aspect must be a finite number > 0"),
    (render, dict(aspect="wide"), TypeError, "aspect must be a number, not str"),
    (render, dict(integrator="whitted"), ValueError, "integrator must be one of course, path"),
    (render, dict(integrator=3), TypeError, "integrator must be a str"),
    (render, dict(features="yes"), TypeError, "features must be True or False"),
    (render, dict(progress=5), TypeError, "progress must be callable"),
    (render, dict(device="tpu"), ValueError, "device must be one of cpu, gpu, got 'tpu'"),
    (render, dict(device=None), TypeError, "device must be a str"),
    (render, dict(background=(1, 2)), ValueError, "background must have three components"),
    (render, dict(background=(-1, 0, 0)), ValueError, "background components must be finite"),
    (render, dict(background="red"), TypeError, "background must be three numbers"),
    (render, dict(depth=-1), ValueError, "depth must be a finite number >= 0, got -1"),
    (render, dict(depth="far"), TypeError, "depth must be a number"),
    (render, dict(aperture=float("nan"), depth=2), ValueError, "aperture must be a finite"),
    (render, dict(aperture=0.1), ValueError, "aperture needs depth of field"),
    (glint.render, dict(scene=glint.BALL), TypeError, "scene must be a glint.Scene"),
    # Scene.render_settings, the native method.
    (BALL.render_settings, dict(width=-5), ValueError, "width must be between 1 and 65535"),
    (BALL.render_settings, dict(spp=2.5), TypeError, "spp must be an int, not float"),
    (BALL.render_settings, dict(integrator=1), TypeError, "integrator must be a str"),
    # glint.load_scene and friends.
    (glint.load_scene, dict(path=3), TypeError, "path must be a path (str or os.PathLike)"),
    (glint.load_scene, dict(path=THREE_SPHERES, env_strength=-1), ValueError, "env_strength"),
    (glint.load_scene, dict(path=THREE_SPHERES, scene=-1), ValueError, "scene must be at least"),
    (glint.load_scene, dict(path=THREE_SPHERES, scene="0"), TypeError, "scene must be an index"),
    (glint.load_scene, dict(path=THREE_SPHERES, camera=-2), ValueError, "camera must be at least"),
    (glint.load_scene, dict(path=THREE_SPHERES, camera=1.0), TypeError, "camera must be a name"),
    (glint.load_scene, dict(path=THREE_SPHERES, defines=["a"]), TypeError, "defines must be"),
    (glint.load_scene, dict(path=THREE_SPHERES, env=5), TypeError, "env must be a path"),
    (glint.load_scene_text, dict(text=b"{}"), TypeError, "text must be a str, not bytes"),
    (glint.load_scene_text, dict(text="{}", format="yaml"), ValueError, "format must be one of"),
    (glint.load_scene_text, dict(text="{}", base_dir=1), TypeError, "base_dir must be a path"),
    (glint.load_scene_text, dict(text="{}", name=1), TypeError, "name must be a str"),
    (glint.scene_from_dict, dict(scene="{}"), TypeError, "scene must be a dict"),
    (glint.scene_from_dict, dict(scene={"a": {1, 2}}), TypeError, "scene must hold JSON"),
    # glint.tiles
    (glint.tiles, dict(width=0, height=4), ValueError, "width must be between 1 and 65535"),
    (glint.tiles, dict(width=4, height=4, size=0), ValueError, "size must be between 1 and"),
    (glint.tiles, dict(width=4, height=4.5), TypeError, "height must be an int"),
    # glint.write_image
    (glint.write_image, dict(path=None, image=IMAGE), TypeError, "path must be a path"),
    (glint.write_image, dict(path="x.png", image=[[0]]), TypeError, "image must be a numpy"),
    (glint.write_image, dict(path="x.png", image=IMAGE.astype(str)), TypeError, "of numbers"),
    (glint.write_image, dict(path="x.png", image=IMAGE[0]), ValueError, "image must have shape"),
    (glint.write_image, dict(path="x.png", image=IMAGE, exposure=99), ValueError, "-64 and 64"),
    (
        glint.write_image,
        dict(path="x.png", image=IMAGE, exposure="1"),
        TypeError,
        "exposure must be a",
    ),
    (glint.write_image, dict(path="x.png", image=IMAGE, tonemap="filmic"), ValueError, "aces"),
    (glint.write_image, dict(path="x.png", image=IMAGE, transfer="gamma"), ValueError, "srgb"),
    (glint.write_image, dict(path="x.png", image=IMAGE, integrator="x"), ValueError, "course"),
    (glint.write_image, dict(path="x.png", image={"albedo": IMAGE}), ValueError, "'beauty'"),
    # glint.to_srgb8 and glint.denoise
    (glint.to_srgb8, dict(array=IMAGE, exposure=100), ValueError, "exposure must be between"),
    (glint.to_srgb8, dict(array=IMAGE, exposure=None), TypeError, "exposure must be a number"),
    (glint.denoise, dict(color=IMAGE.tolist()), TypeError, "color must be a numpy array"),
    (glint.denoise, dict(color=IMAGE, prefilter="no"), TypeError, "prefilter must be True"),
    (glint.denoise, dict(color=IMAGE, albedo=IMAGE[:2]), ValueError, "albedo has shape"),
]


def case_id(case: tuple) -> str:
    function, kwargs = case[0], case[1]
    return f"{getattr(function, '__name__', 'render')}-{'-'.join(kwargs)}"


@pytest.mark.parametrize("function, kwargs, error, words", CASES, ids=map(case_id, CASES))
def test_a_bad_argument_is_named_with_what_it_accepts(tmp_path, function, kwargs, error, words):
    if function is glint.write_image and isinstance(kwargs["path"], str):
        kwargs = {**kwargs, "path": tmp_path / kwargs["path"]}
    with pytest.raises(error) as caught:
        function(**kwargs)
    assert words in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_numpy_integers_and_floats_are_accepted():
    image = glint.render(BALL, width=np.int64(6), height=np.uint16(4), spp=np.int32(1))
    assert image.shape == (4, 6, 3)
    glint.render(BALL, width=4, height=4, aspect=np.float32(1.5), seed=np.uint64(2**63))
    assert glint.tiles(np.int64(8), 8, size=np.int32(4))[-1] == np.s_[4:8, 4:8]
    assert glint.load_scene(pathlib.Path(THREE_SPHERES)).name == str(THREE_SPHERES)
