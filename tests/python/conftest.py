"""pytest set-up for tests/python: make `import cloudgen_native` work.

The project venv (.venv) already has a .pth file pointing at build/python.
CLOUDGEN_PYTHON_DIR points at another build's python/ directory (for example
build-asan/python); it goes first on sys.path so that build wins. Without
either, build/python of this checkout is appended as a fallback.
"""
import json
import os
import pathlib
import sys

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO_ROOT / "tests"))  # helpers shared with other folders (vdb_voxels)

_override = os.environ.get("CLOUDGEN_PYTHON_DIR")
if _override:
    sys.path.insert(0, os.path.abspath(_override))
else:
    _default = str(REPO_ROOT / "build" / "python")
    if _default not in sys.path:
        sys.path.append(_default)


@pytest.fixture
def out_dir(tmp_path):
    d = tmp_path / "out"
    d.mkdir()
    return d


@pytest.fixture
def inputs(tmp_path):
    """Writes JSON (an object, or text as given) to a file outside the output dir."""
    holder = tmp_path / "in"
    holder.mkdir()

    def make(content, name="in.json"):
        p = holder / name
        p.write_text(content if isinstance(content, str) else json.dumps(content))
        return p
    return make


@pytest.fixture
def params_file(tmp_path):
    """Writes a parameter file (text as given, so it may be malformed) outside the output dir."""
    holder = tmp_path / "params"
    holder.mkdir()

    def make(text, name="p.json"):
        p = holder / name
        p.write_text(text)
        return p
    return make
