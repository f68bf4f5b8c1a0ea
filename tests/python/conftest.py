"""pytest set-up for tests/python: make `import cloudgen_native` work.

The project venv (.venv) already has a .pth file pointing at build/python.
CLOUDGEN_PYTHON_DIR points at another build's python/ directory (for example
build-asan/python); it goes first on sys.path so that build wins. Without
either, build/python of this checkout is appended as a fallback.
"""
import os
import pathlib
import sys

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]

_override = os.environ.get("CLOUDGEN_PYTHON_DIR")
if _override:
    sys.path.insert(0, os.path.abspath(_override))
else:
    _default = str(REPO_ROOT / "build" / "python")
    if _default not in sys.path:
        sys.path.append(_default)
