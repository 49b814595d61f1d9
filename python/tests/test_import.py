"""`import glint` from the source folder's parent (python/) says what happened."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path


def test_importing_the_source_folder_without_its_native_module_says_what_to_do(tmp_path):
    # python/ as a newcomer has it: the package's Python files, no compiled `_glint`.
    source = Path(__file__).resolve().parents[1] / "glint"
    unbuilt = shutil.ignore_patterns("_glint*.so", "__pycache__")
    shutil.copytree(source, tmp_path / "glint", ignore=unbuilt)
    result = subprocess.run(
        [sys.executable, "-c", "import glint"], cwd=tmp_path, capture_output=True, text=True
    )
    assert result.returncode == 1
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: glint's native module is missing")
    assert str(tmp_path / "glint") in last
    assert "maturin develop" in last and "another directory" in last
    assert "circular import" not in last
