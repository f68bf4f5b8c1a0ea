"""`cloudgen bake --ring INNER[,OUTER]`: one level of a nested bake of a layer holds density only in
its square ring INNER <= max(|x|, |y|) < OUTER (plus one voxel), docs/camera.md. Bad values, the
voxels kept, the bake key and --update. Every assertion states its tolerance; failures print the
inputs."""

import json

import pytest
from cli_bake_helpers import bake_keys, grid, run
from test_cli import events, expect_usage_error, listing
from vdb_voxels import read_voxels

# A flat layer 40 x 30 x 1.5 filling its box (as tests/native/test_grid.cpp's layer): at
# --resolution 96 the voxel is 40/96 and the grid 96 x 72 x 4.
LAYER = {"box_size": [40, 30, 1.5], "sheet": 1, "shape_mode": 1}
RES = 96

BAD_RINGS = [
    ("negative", "-1"),
    ("negative outer", "0,-2"),
    ("outer equal", "5,5"),
    ("outer below", "5,2"),
    ("equal as floats", "1,1.00000001"),
    ("nan", "nan"),
    ("nan outer", "1,nan"),
    ("inf", "inf"),
    ("inf outer", "1,inf"),
    ("huge", "1e40"),
    ("garbage", "ring"),
    ("three numbers", "1,2,3"),
    ("empty outer", "1,"),
    ("empty inner", ",2"),
    ("empty", ""),
]


@pytest.mark.parametrize("case,value", BAD_RINGS, ids=[c[0] for c in BAD_RINGS])
def test_bad_ring_values_are_refused(case, value, out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 16, f"--ring={value}", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--ring", "0 <= INNER < OUTER")
    assert listing(out_dir) == [], (case, value)


def test_ring_in_help_and_plan(params_file, out_dir):
    assert "--ring" in run("bake", "--help").stdout
    p = params_file(json.dumps(LAYER))
    ev = events(run("bake", "--params", p, "--resolution", RES, "--ring", "6,14", "--dry-run", "--output",
                    out_dir / "x.vdb"))
    assert ev.plan["ring"] == [6, 14], ev.plan
    ev = events(run("bake", "--params", p, "--resolution", RES, "--ring", "6", "--dry-run", "--output",
                    out_dir / "x.vdb"))
    assert ev.plan["ring"] == [6, None], ev.plan
    ev = events(run("bake", "--params", p, "--resolution", RES, "--dry-run", "--output", out_dir / "x.vdb"))
    assert "ring" not in ev.plan, ev.plan
    assert listing(out_dir) == []


def test_ring_bake_keeps_the_ring_only(params_file, out_dir):
    p = params_file(json.dumps(LAYER))
    plain, ring = out_dir / "plain.vdb", out_dir / "ring.vdb"
    inner, outer = 6.0, 14.0
    r1 = run("bake", "--params", p, "--resolution", RES, "--output", plain)
    r2 = run("bake", "--params", p, "--resolution", RES, "--ring", f"{inner},{outer}", "--output", ring)
    (w1,), (w2,) = events(r1).written, events(r2).written
    # Tiles culled: beyond the outer square 2 columns of 9 tiles (x in +-[16.7, 20]), in the hole
    # 2 x 3 tiles (|x| <= 3.33, |y| <= 5, widened by a voxel: < 6), exact.
    assert w1["tiles_culled"] == 0 and w2["tiles_culled"] == 6 + 18, (w1, w2)
    g1, g2 = grid(plain), grid(ring)
    assert 0 < g2["active_voxels"] < g1["active_voxels"], (g1["active_voxels"], g2["active_voxels"])
    assert g2["active_voxels"] == w2["active_voxels"]
    # The key of the file differs from the plain bake's, and is the one the plan announced.
    k1, k2 = bake_keys([plain, ring])
    assert k1 != k2 and k2 == w2["key"], (k1, k2, w2)

    # Voxel for voxel: a voxel whose centre has inner - voxel <= c < outer + voxel holds the plain
    # bake's value (exact), every other voxel is inactive. Centres computed in double here, in float
    # by the bake: voxels within 1e-4 scene units of either bound are not judged.
    vr, origin, size = read_voxels(ring)
    vp, origin_p, size_p = read_voxels(plain)
    assert (origin, size) == (origin_p, size_p)
    v = size[0]
    eps = 1e-4
    wrong, missing = [], []
    for c, value in vp.items():
        x, y = (origin[a] + c[a] * v for a in range(2))
        cheb = max(abs(x), abs(y))
        lo, hi = cheb - (inner - v), (outer + v) - cheb
        if min(abs(lo), abs(hi)) < eps:
            continue
        if lo > 0 and hi > 0:
            if vr.get(c) != value:
                missing.append((c, cheb, value, vr.get(c)))
        elif c in vr:
            wrong.append((c, cheb, vr[c]))
    assert not missing, f"ring voxels differ from the plain bake (voxel {v}): {missing[:5]}"
    assert not wrong, f"voxels outside [{inner} - voxel, {outer} + voxel) are active: {wrong[:5]}"
    assert set(vr) <= set(vp)


def test_update_rebakes_a_plain_file_as_a_ring(params_file, out_dir):
    p = params_file(json.dumps(LAYER))
    out = out_dir / "x.vdb"
    base = ("bake", "--params", p, "--resolution", 32, "--update", "--output", out)
    assert len(events(run(*base)).written) == 1
    ev = events(run(*base, "--ring", "10"))
    assert len(ev.written) == 1 and not ev.kept, "a ring bake must not keep the plain file"
    ev = events(run(*base, "--ring", "10"))
    assert len(ev.kept) == 1 and not ev.written, "the same ring again is kept"
    ev = events(run(*base, "--ring", "10,1e6"))
    assert len(ev.written) == 1, "another ring is another bake (even one holding the same voxels)"
