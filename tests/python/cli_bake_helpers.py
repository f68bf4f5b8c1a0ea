"""Helpers of the `cloudgen bake` tests (tiers, camera, sequences): bakes run with
--json and are read through addon/cli_events.py (docs/cli_protocol.md)."""
import json
import math
import subprocess
import sys

from test_cli import REPO_ROOT, TIMEOUT, events, info_json
from test_cli import run as run_cli

TIERS_FILE = REPO_ROOT / "native" / "presets" / "tiers.json"
# The cloud the camera bake tests work out by hand (depths, footprints, exact voxel counts): the
# cumulus preset in a 4 x 4 x 2.4 box at Cloud Scale 0.9, its box until 2026-11-29 (now 5 x 5 x 3
# at 0.72, the same field with room above it). The tests pass it with --params (cumulus_args);
# CUMULUS_BOX (origin at the centre) and the Density are that cloud's.
_CUMULUS = json.loads((REPO_ROOT / "native" / "presets" / "clouds.json").read_text())["cumulus"]["params"]
CUMULUS_4X4 = {"preset": "cumulus", "box_size": [4.0, 4.0, 2.4], "cloud_scale": 0.9}
CUMULUS_BOX = tuple(CUMULUS_4X4["box_size"])
CUMULUS_DENSITY = _CUMULUS["density"]
LONGEST = max(CUMULUS_BOX)


def cumulus_args(out_dir):
    """("--params", FILE): CUMULUS_4X4 written to FILE beside a test's output folder (not in it:
    the tests list that folder to find partial files)."""
    path = out_dir.parent / "cumulus_4x4.json"
    path.write_text(json.dumps(CUMULUS_4X4))
    return ("--params", str(path))

# camera_to_cloud of a camera at (0, y, 0) rotated X = +90 degrees (Blender convention):
# camera -Z maps to cloud +y (looks along +y), camera +Y to cloud +z (up).
_C, _S = math.cos(math.radians(90)), math.sin(math.radians(90))


def looking_along_y(y, sign=+1):
    """Camera at (0, y, 0): sign +1 looks along +y (rotation X=+90 deg), -1 along -y (X=-90 deg)."""
    s = sign * _S
    return [[1, 0, 0, 0], [0, _C, -s, y], [0, s, _C, 0], [0, 0, 0, 1]]


# Exact-arithmetic camera: rows of 0/±1, eye at y=-6, so the nearest visible point (front
# face y=-2) is at depth 4 exactly and footprint = 2*4*(0.0625/4) = 0.125 = 4/32 exactly,
# the voxel of a uniform --resolution 32 bake. Narrow: half width 0.0625*depth.
NARROW = {"camera_to_cloud": [[1, 0, 0, 0], [0, 0, -1, -6], [0, 1, 0, 0], [0, 0, 0, 1]],
          "tan_half_fov": [0.0625, 0.0625], "resolution": [4, 4], "margin": 0}



def run(*args):
    """`cloudgen ARGS`; bakes speak the JSON-lines protocol (--json added)."""
    if args and args[0] == "bake" and "--json" not in args:
        args = (*args, "--json")
    return run_cli(*args)


def grid(path):
    (g,) = info_json(path)["grids"]
    return g


def camera_lines(result):
    """(depth, footprint, voxel, margin) or None, and (voxel, visible tiles, total tiles) of
    a camera bake, from its `camera` and `wrote` events."""
    assert result.returncode == 0, (result.returncode, result.stdout, result.stderr)
    ev = events(result)
    assert ev.camera is not None and len(ev.written) == 1, f"no camera/wrote event in:\n{result.stdout}"
    cam, wrote = ev.camera, ev.written[0]
    fit = (cam["nearest_depth"], cam["footprint"], cam["voxel"], cam["margin"]) if cam["visible"] else None
    return fit, (wrote["voxel"], wrote["tiles_total"] - wrote["tiles_culled"], wrote["tiles_total"])


def bake_keys(paths):
    """cloudgen_bake_key of each file: one openvdb child process for all of them (cheaper than a
    `cloudgen info` per file), else `cloudgen info --json` per file."""
    script = ("import json, sys, openvdb\n"
              "print(json.dumps([openvdb.readAllGridMetadata(p)[0]['cloudgen_bake_key'] for p in sys.argv[1:]]))")
    r = subprocess.run([sys.executable, "-c", script, *map(str, paths)], capture_output=True, text=True,
                       timeout=TIMEOUT)
    if r.returncode == 0:
        return json.loads(r.stdout.splitlines()[-1])
    assert "No module named 'openvdb'" in r.stderr, r.stderr
    return [grid(p)["metadata"]["cloudgen_bake_key"] for p in paths]


