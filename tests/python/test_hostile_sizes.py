"""Sizes that once overflowed or hung (issue 15, findings 4 and 6): the memory
estimate never wraps (--resolution 1000000 once printed "-8589934592 GiB" and
started a bake of 10^18 voxels) and camera files with tiny pixel footprints
(near 1e-6, tiny pixels, the camera inside the box) are refused up front with
one line instead of hanging or failing at write time.

Tolerance: none. The timeout (120 s) catches hangs only; before the fix the
first case ran until killed."""
import json
import os
import pathlib
import re
import subprocess

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(REPO_ROOT / "build" / "bin" / "cloudgen"))
TIMEOUT = int(os.environ.get("CLOUDGEN_HANG_TIMEOUT", "120"))

if not os.access(CLOUDGEN, os.X_OK):
    pytest.skip(f"cloudgen binary not built: {CLOUDGEN}", allow_module_level=True)


def run(*args):
    return subprocess.run([CLOUDGEN, *map(str, args)], capture_output=True, text=True, timeout=TIMEOUT)


def one_line_usage_error(r, *words):
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and lines[0].startswith("cloudgen: error:"), r.stderr[-800:]
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("box", [[4, 4, 3], [4, 4, 4], [1e5, 1e5, 1e5], [0.001, 0.001, 0.001]])
@pytest.mark.parametrize("resolution", [100000, 1000000])
def test_huge_resolution_refused_with_a_positive_estimate(tmp_path, box, resolution):
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"preset": "cumulus", "box_size": box}))
    r = run("bake", "--params", params, "--resolution", resolution, "--output", tmp_path / "x.vdb")
    line = one_line_usage_error(r, "--resolution")
    if box[0] < 0.01:  # voxels below OpenVDB's smallest scale: refused before the estimate
        assert "smaller than 1e-07" in line, line
    else:
        gib = re.search(r"estimated (\S+) GiB", line)
        assert gib and float(gib.group(1)) > 8, f"box {box}, resolution {resolution}: {line}"
    assert not list(tmp_path.glob("*.vdb")), "a file was left"


def camera(tmp_path, **changes):
    doc = {"camera_to_cloud": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 10], [0, 0, 0, 1]],
           "tan_half_fov": [0.4, 0.3], "resolution": [640, 480], **changes}
    path = tmp_path / "cam.json"
    path.write_text(json.dumps(doc))
    return path


INSIDE = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
CASES = {
    "inside the box, near 1e-6": dict(camera_to_cloud=INSIDE, near=1e-6),
    "inside the box, near 1e-3": dict(camera_to_cloud=INSIDE, near=1e-3, resolution=[4096, 4096]),
    "tiny pixels at the box": dict(camera_to_cloud=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.6], [0, 0, 0, 1]],
                                   tan_half_fov=[1e-4, 1e-4], resolution=[65536, 65536]),
    "inside, many pixels": dict(camera_to_cloud=INSIDE, near=1e-6, resolution=[65536, 65536]),
}


@pytest.mark.parametrize("case", CASES)
def test_tiny_pixel_footprint_refused_up_front(tmp_path, case):
    cam = camera(tmp_path, **CASES[case])
    r = run("bake", "--preset", "cumulus", "--camera", cam, "--output", tmp_path / "c.vdb")
    one_line_usage_error(r, "--camera", "finer than")
    # with --resolution as the cap the same camera is bounded: refused by the memory guard or baked
    r = run("bake", "--preset", "cumulus", "--camera", cam, "--resolution", 1000000, "--output", tmp_path / "c.vdb")
    one_line_usage_error(r, "--camera", "GiB")
    assert not list(tmp_path.glob("*.vdb")), "a file was left"
