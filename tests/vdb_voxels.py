"""Voxel values of a VDB, read with the `openvdb` Python module that ships in the
bpy wheel of .venv, in a child process (its bindings report leaks at exit).
Shared by the CLI tests and the distributed-bake tests; skips where openvdb is missing."""
import json
import subprocess
import sys

import pytest

_SCRIPT = r"""
import json, sys, itertools
import openvdb
g = openvdb.read(sys.argv[1], "density")
out = {}
for it in g.citerOnValues():
    lo, hi = it.min, it.max
    for c in itertools.product(*(range(lo[a], hi[a] + 1) for a in range(3))):  # tiles: every voxel
        out[",".join(map(str, c))] = float(it.value)
print(json.dumps({"voxels": out, "origin": list(g.transform.indexToWorld((0, 0, 0))),
                  "voxel": list(g.transform.voxelSize())}))
"""


def read_voxels(path, timeout=120):
    """({(i, j, k): value} of the active voxels of grid `density`, world position of index
    (0, 0, 0), voxel size)."""
    r = subprocess.run([sys.executable, "-c", _SCRIPT, str(path)], capture_output=True, text=True, timeout=timeout)
    if r.returncode != 0 and "No module named 'openvdb'" in r.stderr:
        pytest.skip("openvdb Python module not available")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout.splitlines()[-1])
    voxels = {tuple(int(x) for x in k.split(",")): v for k, v in doc["voxels"].items()}
    return voxels, tuple(doc["origin"]), tuple(doc["voxel"])
