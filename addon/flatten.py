"""Package-side stand-in for osl/flatten.py.

blender_nodes.py (copied unchanged from osl/ by scripts/package_addon.py; it
holds the Script-node wiring, kept in one place) asks `flatten.shader_source`
for a shader's self-contained text. In the repository that flattens
osl/*.osl; in the add-on the flattened sources are already in shaders/.
"""
from __future__ import annotations

from . import bridge

SHADERS = ("cloud_noise", "cloud_main", "cloud_height")


def shader_source(name: str, defines: dict | None = None) -> str:
    if name not in SHADERS:
        raise ValueError(f"unknown shader {name!r}; expected one of {SHADERS}")
    head = "".join(f"#define {k} {v}\n" for k, v in (defines or {}).items())
    return head + bridge.shader_source(name)
