"""Inline the shared headers into one self-contained OSL source.

The OSL shaders include the shared C++/OSL model (native/include/cloudgen/shared/)
with relative #include lines. Blender's internal text datablocks and copies of
a shader outside the repository cannot resolve those, so the add-on and the
tests use the flattened text: every `#include "..."` replaced by the file's
contents (resolved relative to the including file, each file once — they all
have include guards anyway).
"""
from __future__ import annotations

import pathlib
import re
import sys

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
OSL_DIR = pathlib.Path(__file__).resolve().parent
SHADERS = ("cloud_noise", "cloud_main", "cloud_height")


def flatten(path: str | pathlib.Path, _seen: set | None = None) -> str:
    path = pathlib.Path(path).resolve()
    seen = set() if _seen is None else _seen
    if path in seen:
        return ""
    seen.add(path)
    out = []
    for line in path.read_text().splitlines():
        m = _INCLUDE.match(line)
        if m:
            target = (path.parent / m.group(1)).resolve()
            if not target.is_file():
                raise FileNotFoundError(f"{path}: cannot resolve #include \"{m.group(1)}\"")
            out.append(f"// ---- begin {m.group(1)}")
            out.append(flatten(target, seen))
            out.append(f"// ---- end {m.group(1)}")
        else:
            out.append(line)
    return "\n".join(out) + "\n"


def shader_source(name: str, defines: dict | None = None) -> str:
    """The flattened source of one of our shaders, e.g. shader_source("cloud_main").
    `defines` are prepended as #define lines (e.g. {"CG_NO_EARLY_EXIT": 1})."""
    if name not in SHADERS:
        raise ValueError(f"unknown shader {name!r}; expected one of {SHADERS}")
    head = "".join(f"#define {k} {v}\n" for k, v in (defines or {}).items())
    return head + flatten(OSL_DIR / f"{name}.osl")


if __name__ == "__main__":
    sys.stdout.write(flatten(sys.argv[1]))
