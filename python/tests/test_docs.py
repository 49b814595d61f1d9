"""The docstrings' examples run, and every public name is documented and typed."""

from __future__ import annotations

import doctest
import inspect
import os
import subprocess
import sys

import pytest

import glint
import glint._glint


def test_docstring_examples_run():
    results = doctest.testmod(
        glint, extraglobs={"glint": glint}, optionflags=doctest.ELLIPSIS, verbose=False
    )
    assert results.failed == 0
    assert results.attempted >= 20


def test_every_public_name_is_documented():
    for name in glint.__all__:
        value = getattr(glint, name)
        if callable(value):
            assert inspect.getdoc(value), name
    for name in ("name", "warnings"):
        assert inspect.getdoc(getattr(glint.Scene, name)), name


def test_the_stubs_match_the_native_module():
    """mypy's stubtest compares glint/_glint.pyi with what the compiled module has."""
    try:
        import mypy.stubtest  # noqa: F401
    except ImportError:
        if os.environ.get("CI"):
            raise
        pytest.skip("SKIPPED: mypy is not installed")
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "glint._glint"],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr
