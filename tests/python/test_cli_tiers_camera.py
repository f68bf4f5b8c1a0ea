"""`cloudgen tiers`, `bake --quality`, the camera-aware bake (`bake --camera`) and
sequence bakes that copy or keep unchanged frames (`--frames`, `--sequence`,
`--update`, the `cloudgen_bake_key` metadata).

Interfaces: `cloudgen bake --help`, docs/camera.md and docs/cli_protocol.md (bakes
here run with --json and are read through addon/cli_events.py). Every assertion states its tolerance; failures print the
inputs. Resolutions stay <= 48 (the draft tier's own 64 excepted) so the file runs
in a few seconds. No test asserts how long anything takes.

Voxel values are read back with the `openvdb` Python module that ships inside the
bpy wheel of .venv, in a child process (its bindings report leaks at exit); the
tests that need it are skipped where it is missing.
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from test_cli import REPO_ROOT, TIMEOUT, cli_events, events, expect_usage_error, info_json, listing
from test_cli import run as run_cli

sys.path.insert(0, str(REPO_ROOT / "tests"))
from vdb_voxels import read_voxels  # noqa: E402

TIERS_FILE = REPO_ROOT / "native" / "presets" / "tiers.json"
CUMULUS_BOX = (4.0, 4.0, 3.0)  # cumulus preset box_size: origin at the centre, x/y in [-2, 2], z in [-1.5, 1.5]
LONGEST = 4.0

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


# ------------------------------------------------------------------ tiers ---

def test_tiers_lists_draft_preview_final():
    # Tolerance: exact (names in file order, each on its own line start).
    r = run("tiers")
    assert r.returncode == 0, r.stderr
    names = [line.split()[0] for line in r.stdout.splitlines() if line and not line[0].isspace()]
    assert names == ["draft", "preview", "final"], r.stdout
    expected = json.loads(TIERS_FILE.read_text())
    for name, tier in expected.items():
        assert f"resolution {tier['bake']['resolution']}" in r.stdout, (name, r.stdout)


def test_tiers_json_is_the_data_file():
    # Tolerance: exact (parsed JSON equal, key order of the file kept at the top level).
    r = run("tiers", "--json")
    assert r.returncode == 0, r.stderr
    printed = json.loads(r.stdout)
    expected = json.loads(TIERS_FILE.read_text())
    assert printed == expected, (printed, expected)
    assert list(printed) == list(expected) == ["draft", "preview", "final"]


def test_tiers_refuses_unknown_option():
    expect_usage_error(run("tiers", "--bogus"), "--bogus")


def test_bake_quality_draft_takes_the_tier_settings(out_dir):
    tier = json.loads(TIERS_FILE.read_text())["draft"]["bake"]
    out = out_dir / "draft.vdb"
    r = run("bake", "--preset", "cumulus", "--quality", "draft", "--output", out)
    assert r.returncode == 0, (r.stdout, r.stderr)
    g = grid(out)
    # Voxel = longest side / tier resolution. Tolerance 1e-9 relative (float32 of 4/64 is exact).
    expected_voxel = LONGEST / tier["resolution"]
    assert g["voxel_size"] == pytest.approx([expected_voxel] * 3, rel=1e-9), (g["voxel_size"], tier)
    assert g["metadata"]["cloudgen_resolution"] == str(tier["resolution"]), g["metadata"]
    # Half floats (the draft tier says so) — exact flags.
    assert tier["half"] is True
    assert g["half"] is True and g["metadata"]["is_saved_as_half_float"] == "true", g
    # Voxels <= tolerance are dropped: every active value exceeds it (exact comparison; a float32
    # value > 0.01 rounds to a half >= 0.0100021 > 0.01, so half storage cannot break it).
    assert g["active_voxels"] > 0
    assert g["min"] > tier["tolerance"], (g["min"], tier)


def test_explicit_options_win_over_the_tier(out_dir):
    tier = json.loads(TIERS_FILE.read_text())["draft"]["bake"]
    out = out_dir / "d16.vdb"
    r = run("bake", "--preset", "cumulus", "--quality", "draft", "--resolution", 16, "--output", out, "--quiet")
    assert r.returncode == 0, r.stderr
    g = grid(out)
    # --resolution wins (tolerance 1e-9 relative); half and the drop tolerance still come from the tier.
    assert g["voxel_size"] == pytest.approx([LONGEST / 16] * 3, rel=1e-9), g["voxel_size"]
    assert g["half"] is True and g["min"] > tier["tolerance"], g
    # The same bake spelled out has the same bake key (exact string).
    out2 = out_dir / "explicit.vdb"
    r = run("bake", "--preset", "cumulus", "--resolution", 16, "--half", "--tolerance", tier["tolerance"],
            "--output", out2, "--quiet")
    assert r.returncode == 0, r.stderr
    assert grid(out2)["metadata"]["cloudgen_bake_key"] == g["metadata"]["cloudgen_bake_key"]
    # --tolerance 0 wins too: the faint edge of the cumulus (values below 0.01) is kept.
    out3 = out_dir / "tol0.vdb"
    r = run("bake", "--preset", "cumulus", "--quality", "draft", "--resolution", 16, "--tolerance", 0,
            "--output", out3, "--quiet")
    assert r.returncode == 0, r.stderr
    g3 = grid(out3)
    assert g3["active_voxels"] > g["active_voxels"] and g3["min"] <= tier["tolerance"], (g3, g)


def test_unknown_tier_refused_listing_the_tiers(out_dir):
    r = run("bake", "--preset", "cumulus", "--quality", "ultra", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--quality", "ultra", "draft", "preview", "final")
    assert listing(out_dir) == []


def test_no_resolution_quality_or_camera_refused(out_dir):
    r = run("bake", "--preset", "cumulus", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--resolution", "--quality", "--camera")
    assert listing(out_dir) == []


# ----------------------------------------------------------------- camera ---

# (tan_half_fov, resolution): footprint = 2 * depth * min(tx / w, ty / h), depth 6 in both;
# the first is limited by both axes equally, the second by the vertical one.
FOV_CASES = [([0.36, 0.27], [40, 30]), ([0.5, 0.27], [40, 30])]


@pytest.mark.parametrize("fov,res", FOV_CASES, ids=["square-pixels", "vertical-limits"])
def test_camera_voxel_is_the_pixel_footprint_at_the_nearest_depth(fov, res, inputs, out_dir):
    cam = {"camera_to_cloud": looking_along_y(-8.0), "tan_half_fov": fov, "resolution": res}
    out = out_dir / "cam.vdb"
    r = run("bake", "--preset", "cumulus", "--camera", inputs(cam), "--output", out)
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit is not None, r.stdout
    depth, footprint, fit_voxel, margin = fit
    # Hand computation: the eye at y=-8, the front face of the 4x4x3 box at y=-2 (inside the
    # view: half width 0.36*6 > 2, half height 0.27*6 > 1.5) -> depth 6.
    expected_depth = 6.0
    expected_fp = 2 * expected_depth * min(fov[0] / res[0], fov[1] / res[1])
    # Default margin (camera.h): 16 / peak extinction, extinction = Density x 20 per unit,
    # at most the longest side: min(16 / (0.5 * 20), 4) = 1.6.
    rel = 1e-3  # the lines print 6 significant digits; float32 arithmetic inside
    assert depth == pytest.approx(expected_depth, rel=rel), (cam, r.stdout)
    assert footprint == pytest.approx(expected_fp, rel=rel), (cam, r.stdout)
    assert fit_voxel == pytest.approx(expected_fp, rel=rel) and voxel == pytest.approx(expected_fp, rel=rel)
    assert margin == pytest.approx(1.6, rel=rel), r.stdout
    assert 0 < visible <= total
    g = grid(out)
    assert g["voxel_size"] == pytest.approx([expected_fp] * 3, rel=rel), (cam, g["voxel_size"])
    assert g["active_voxels"] > 0


def test_camera_pixels_per_voxel_and_margin(inputs, out_dir):
    base = {"camera_to_cloud": looking_along_y(-8.0), "tan_half_fov": [0.36, 0.27], "resolution": [40, 30]}
    r1 = run("bake", "--preset", "cumulus", "--camera", inputs(base, "a.json"), "--output", out_dir / "a.vdb")
    r2 = run("bake", "--preset", "cumulus", "--camera", inputs({**base, "pixels_per_voxel": 2, "margin": 0.5},
                                                              "b.json"), "--output", out_dir / "b.vdb")
    (_, fp1, v1, _), _ = camera_lines(r1)
    (_, fp2, v2, m2), _ = camera_lines(r2)
    # Tolerance 1e-3 relative (6 printed digits): same footprint, twice the voxel, margin as given.
    assert fp2 == pytest.approx(fp1, rel=1e-3) and v2 == pytest.approx(2 * v1, rel=1e-3), (r1.stdout, r2.stdout)
    assert m2 == pytest.approx(0.5, rel=1e-3), r2.stdout
    assert grid(out_dir / "b.vdb")["voxel_size"][0] == pytest.approx(2 * grid(out_dir / "a.vdb")["voxel_size"][0],
                                                                     rel=1e-6)


def test_camera_resolution_caps_the_voxel(inputs, out_dir):
    cam = inputs({"camera_to_cloud": looking_along_y(-8.0), "tan_half_fov": [0.36, 0.27], "resolution": [40, 30]})
    # Camera wants 0.108 (38 voxels along 4); a cap of 16 voxels makes it 0.25; a cap of 48
    # is finer than the camera and leaves 0.108. Tolerance 1e-6 relative.
    for cap, expected in ((16, LONGEST / 16), (48, 0.108)):
        out = out_dir / f"cap{cap}.vdb"
        r = run("bake", "--preset", "cumulus", "--camera", cam, "--resolution", cap, "--output", out)
        _, (voxel, _, _) = camera_lines(r)
        g = grid(out)
        assert g["voxel_size"][0] >= LONGEST / cap * (1 - 1e-6), (cap, g["voxel_size"])
        assert g["voxel_size"][0] == pytest.approx(expected, rel=1e-6), (cap, g["voxel_size"], r.stdout)
        assert voxel == pytest.approx(expected, rel=1e-3), (cap, r.stdout)


def test_camera_inside_the_box_needs_the_cap(inputs, out_dir):
    # Eye at the box centre: nearest depth = near clip 0.5, voxel 2*0.5*0.009 = 0.009,
    # ~445x445x334 voxels -> refused by a 0.05 GiB memory budget naming --camera; capped it bakes.
    cam = inputs({"camera_to_cloud": looking_along_y(0.0), "tan_half_fov": [0.36, 0.27], "resolution": [40, 30],
                  "near": 0.5})
    r = run("bake", "--preset", "cumulus", "--camera", cam, "--max-memory", 0.05, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", "GiB", "--max-memory")
    assert listing(out_dir) == []
    r = run("bake", "--preset", "cumulus", "--camera", cam, "--resolution", 32, "--output", out_dir / "x.vdb")
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit is not None and fit[0] == pytest.approx(0.5, rel=1e-3), r.stdout  # depth = near clip
    assert voxel == pytest.approx(LONGEST / 32, rel=1e-3), r.stdout


def test_camera_looking_away_bakes_an_empty_file(inputs, out_dir):
    cam = inputs({"camera_to_cloud": looking_along_y(-8.0, sign=-1), "tan_half_fov": [0.36, 0.27],
                  "resolution": [40, 30]})
    out = out_dir / "away.vdb"
    r = run("bake", "--preset", "cumulus", "--camera", cam, "--output", out)
    assert r.returncode == 0, (r.stdout, r.stderr)
    fit, (_, visible, total) = camera_lines(r)
    assert fit is None and visible == 0 and total > 0, r.stdout  # the cloud box is outside the view
    g = grid(out)
    assert g["name"] == "density" and g["active_voxels"] == 0, g  # exact


def test_narrow_camera_bakes_a_subset_of_the_uniform_bake(inputs, out_dir):
    """Exact: the camera bake's voxel (0.125) equals the --resolution 32 bake's, both grids
    start at the box corner, and every active voxel of the camera bake is active in the uniform
    bake with a bit-identical value; every uniform voxel whose centre is inside the view is
    in the camera bake (its tile intersects the frustum, margin 0)."""
    cam_out, uni_out = out_dir / "cam.vdb", out_dir / "uni.vdb"
    r = run("bake", "--preset", "cumulus", "--camera", inputs(NARROW), "--output", cam_out)
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit[0] == 4.0 and voxel == 0.125, r.stdout  # exact (printed %g of exact binary values)
    assert 0 < visible < total, r.stdout
    r = run("bake", "--preset", "cumulus", "--resolution", 32, "--output", uni_out, "--quiet")
    assert r.returncode == 0, r.stderr
    cam_vox, cam_origin, cam_size = read_voxels(cam_out)
    uni_vox, uni_origin, uni_size = read_voxels(uni_out)
    assert cam_size == uni_size == (0.125,) * 3 and cam_origin == uni_origin, (cam_size, uni_size, cam_origin)
    assert 0 < len(cam_vox) < len(uni_vox), (len(cam_vox), len(uni_vox))
    missing = set(cam_vox) - set(uni_vox)
    assert not missing, f"camera-only voxels: {sorted(missing)[:5]}"
    diff = [(c, cam_vox[c], uni_vox[c]) for c in cam_vox if cam_vox[c] != uni_vox[c]]
    assert not diff, f"values differ (tolerance exact): {diff[:5]}"
    # Completeness where visible: centres strictly inside the view frustum (by 1e-3 units)
    # of the camera at (0,-6,0) looking along +y with tan 0.0625 must all be baked.
    inside = []
    for c in uni_vox:
        x, y, z = (uni_origin[a] + c[a] * 0.125 for a in range(3))
        depth = y + 6.0
        if depth > 0.1 + 1e-3 and abs(x) < 0.0625 * depth - 1e-3 and abs(z) < 0.0625 * depth - 1e-3:
            inside.append(c)
    assert inside, "the view sees some cloud"
    lost = [c for c in inside if c not in cam_vox]
    assert not lost, f"visible voxels not baked: {lost[:5]}"


def test_lod_bake_equals_module_density_with_footprint(out_dir):
    # Exact: a LOD bake's voxel values are density(..., footprint=voxel) at the voxel centres
    # (centre = (i,j,k)*voxel + origin + voxel/2, float32, as `cloudgen bake --help` says).
    cn = pytest.importorskip("cloudgen_native")
    out = out_dir / "u.vdb"
    r = run("bake", "--preset", "cumulus", "--resolution", 32, "--output", out, "--quiet")
    assert r.returncode == 0, r.stderr
    vox, _, _ = read_voxels(out)
    coords = np.array(sorted(vox), dtype=np.float32)
    values = np.array([vox[tuple(int(v) for v in c)] for c in coords], dtype=np.float32)
    v = np.float32(0.125)
    corner = -np.array(CUMULUS_BOX, dtype=np.float32) / np.float32(2)
    centres = (coords * v + corner + v / np.float32(2)).astype(np.float32)
    got = cn.density({"preset": "cumulus"}, centres, footprint=0.125)
    bad = np.flatnonzero(got != values)
    assert bad.size == 0, [(coords[i].tolist(), float(values[i]), float(got[i])) for i in bad[:5]]


def test_light_directions_keep_more_tiles(inputs, out_dir):
    # margin 0: without lights only the view frustum; with a sun above and to the side the
    # frustum is swept towards it (shadow casters kept). Exact counts compared.
    r0 = run("bake", "--preset", "cumulus", "--camera", inputs(NARROW, "n0.json"), "--output", out_dir / "n0.vdb")
    lit = {**NARROW, "light_directions": [[0.3, 0.2, 1.0]]}
    r1 = run("bake", "--preset", "cumulus", "--camera", inputs(lit, "n1.json"), "--output", out_dir / "n1.vdb")
    _, (v0, vis0, tot0) = camera_lines(r0)
    _, (v1, vis1, tot1) = camera_lines(r1)
    assert v0 == v1 and tot0 == tot1, (r0.stdout, r1.stdout)
    assert vis0 < vis1 <= tot1, (r0.stdout, r1.stdout)
    assert grid(out_dir / "n1.vdb")["active_voxels"] > grid(out_dir / "n0.vdb")["active_voxels"]


_GOOD = {"camera_to_cloud": [[1, 0, 0, 0], [0, 0, -1, -8], [0, 1, 0, 0], [0, 0, 0, 1]],
         "tan_half_fov": [0.36, 0.27], "resolution": [40, 30]}
BAD_CAMERAS = [
    ("missing key", {k: v for k, v in _GOOD.items() if k != "resolution"}, ["missing", "resolution"]),
    ("scaled matrix", {**_GOOD, "camera_to_cloud": [[2, 0, 0, 0], [0, 0, -2, -8], [0, 2, 0, 0], [0, 0, 0, 1]]},
     ["camera_to_cloud", "rigid"]),
    ("bottom row", {**_GOOD, "camera_to_cloud": [[1, 0, 0, 0], [0, 0, -1, -8], [0, 1, 0, 0], [1, 0, 0, 1]]},
     ["camera_to_cloud", "last row"]),
    ("ORTHO", {**_GOOD, "type": "ORTHO"}, ["perspective", "ORTHO"]),
    ("unknown key", {**_GOOD, "fov": 1.0}, ["unknown key", "fov"]),
    ("bad JSON", '{"camera_to_cloud": [[1, 0, 0, 0], ', ["JSON"]),
    ("resolution float", {**_GOOD, "resolution": [40.5, 30]}, ["resolution"]),
    ("pixels_per_voxel zero", {**_GOOD, "pixels_per_voxel": 0}, ["pixels_per_voxel"]),
    ("zero light", {**_GOOD, "light_directions": [[0, 0, 0]]}, ["light_directions"]),
]


@pytest.mark.parametrize("case,content,words", BAD_CAMERAS, ids=[c[0] for c in BAD_CAMERAS])
def test_bad_camera_files(case, content, words, inputs, out_dir):
    path = inputs(content, "cam.json")
    r = run("bake", "--preset", "cumulus", "--camera", path, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", *words)
    assert listing(out_dir) == []


def test_missing_camera_file(out_dir):
    r = run("bake", "--preset", "cumulus", "--camera", out_dir / "nope.json", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", "nope.json")
    assert listing(out_dir) == []


# -------------------------------------------------------------- sequences ---

STILL = {"preset": "cumulus", "evolution": 0, "wind_strength": 0}


def lines_of(result, verb):
    """The `verb` events (wrote, copied, kept) of a --json bake, as (path, source frame or None)."""
    ev = events(result)
    chosen = {"wrote": ev.written, "copied": ev.copied, "kept": ev.kept}[verb]
    return [(e["path"], e.get("source_frame")) for e in chosen]


def test_still_cloud_frames_are_copied_then_kept(inputs, out_dir):
    params = inputs(STILL, "still.json")
    pattern = out_dir / "s.vdb"
    args = ("bake", "--params", params, "--frames", "1-4", "--resolution", 16, "--output", pattern)
    r = run(*args)
    assert r.returncode == 0, (r.stdout, r.stderr)
    names = [f"s_{n:04d}.vdb" for n in range(1, 5)]
    assert listing(out_dir) == names
    assert lines_of(r, "wrote") == [(str(out_dir / names[0]), None)], r.stdout
    assert len(lines_of(r, "wrote")) == 1, r.stdout
    assert lines_of(r, "copied") == [(str(out_dir / n), 1) for n in names[1:]], r.stdout
    data = [(out_dir / n).read_bytes() for n in names]
    assert all(d == data[0] for d in data), "copied frames are byte-identical to frame 1"

    # --update: every stored bake key matches -> all kept, files untouched (exact bytes).
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert lines_of(r, "kept") == [(str(out_dir / n), None) for n in names], r.stdout
    assert not lines_of(r, "wrote") and not lines_of(r, "copied"), r.stdout
    assert [(out_dir / n).read_bytes() for n in names] == data

    # A deleted frame comes back as a copy of a kept one.
    (out_dir / names[2]).unlink()
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "kept")) == 3, r.stdout
    assert lines_of(r, "copied") == [(str(out_dir / names[2]), 1)], r.stdout
    assert (out_dir / names[2]).read_bytes() == data[0]

    # Change the density: the stored keys no longer match -> baked again, not kept.
    params.write_text(json.dumps({**STILL, "density": 0.3}))
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert not lines_of(r, "kept"), r.stdout
    assert len(lines_of(r, "wrote")) == 1 and len(lines_of(r, "copied")) == 3, r.stdout
    stored = json.loads(grid(out_dir / names[0])["metadata"]["cloudgen_params"])["density"]
    assert stored == pytest.approx(0.3, rel=1e-6), stored  # float32 round trip
    assert all((out_dir / n).read_bytes() == (out_dir / names[0]).read_bytes() for n in names[1:])


def test_evolving_cloud_frames_are_all_baked(out_dir):
    pattern = out_dir / "e.vdb"
    args = ("bake", "--preset", "cumulus", "--frames", "1-4", "--resolution", 16, "--output", pattern)
    r = run(*args)  # cumulus: evolution 0.1, so time changes the field
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "wrote")) == 4 and not lines_of(r, "copied"), r.stdout
    keys = bake_keys([out_dir / f"e_{n:04d}.vdb" for n in range(1, 5)])
    assert len(set(keys)) == 4, keys
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "kept")) == 4 and not lines_of(r, "wrote"), r.stdout
    # Another resolution is another bake: --update re-bakes every frame.
    r = run("bake", "--preset", "cumulus", "--frames", "1-4", "--resolution", 20, "--output", pattern, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "wrote")) == 4 and not lines_of(r, "kept"), r.stdout


def test_update_rebakes_an_unreadable_file(out_dir):
    out = out_dir / "x.vdb"
    out.write_text("not a vdb")
    r = run("bake", "--preset", "cumulus", "--resolution", 16, "--output", out, "--update", "--quiet")
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert lines_of(r, "wrote"), r.stdout
    assert grid(out)["active_voxels"] > 0


def test_sequence_file_per_frame_params(inputs, out_dir):
    seq = {"fps": 24, "frames": [
        {"frame": 1, "params": {"preset": "cumulus", "density": 0.4}},
        {"frame": 2, "params": {"preset": "cumulus", "density": 0.4}},
        {"frame": 3, "params": {"preset": "cumulus", "density": 0.6}}]}
    r = run("bake", "--sequence", inputs(seq, "seq.json"), "--resolution", 16, "--output", out_dir / "q_##.vdb")
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert listing(out_dir) == ["q_01.vdb", "q_02.vdb", "q_03.vdb"]
    verbs = [(e["event"], e["path"], e.get("source_frame"))
             for e in map(cli_events.parse, r.stdout.splitlines()) if e["event"] in ("wrote", "copied", "kept")]
    assert verbs == [("wrote", str(out_dir / "q_01.vdb"), None), ("copied", str(out_dir / "q_02.vdb"), 1),
                     ("wrote", str(out_dir / "q_03.vdb"), None)], r.stdout
    for name, density in (("q_01.vdb", 0.4), ("q_02.vdb", 0.4), ("q_03.vdb", 0.6)):
        stored = json.loads(grid(out_dir / name)["metadata"]["cloudgen_params"])["density"]
        assert stored == pytest.approx(density, rel=1e-6), (name, stored)  # float32 round trip


BAD_SEQUENCES = [
    ("duplicate frame", {"frames": [{"frame": 1, "params": {}}, {"frame": 1, "params": {}}]},
     ["--sequence", "frame 1", "twice"]),
    ("missing params", {"frames": [{"frame": 1}]}, ["--sequence", "params"]),
    ("unknown key", {"frames": [{"frame": 1, "params": {}}], "fsp": 24}, ["--sequence", "fsp"]),
    ("bad param", {"frames": [{"frame": 1, "params": {"densty": 1}}]}, ["--sequence", "densty"]),
    ("bad JSON", '{"frames": [', ["--sequence", "JSON"]),
]


@pytest.mark.parametrize("case,content,words", BAD_SEQUENCES, ids=[c[0] for c in BAD_SEQUENCES])
def test_bad_sequence_files(case, content, words, inputs, out_dir):
    r = run("bake", "--sequence", inputs(content, "seq.json"), "--resolution", 16, "--output", out_dir / "x.vdb")
    expect_usage_error(r, *words)
    assert listing(out_dir) == []


@pytest.mark.parametrize("extra", [["--preset", "cumulus"], ["--frames", "1-2"]], ids=["preset", "frames"])
def test_sequence_excludes_other_sources(extra, inputs, out_dir):
    seq = inputs({"frames": [{"frame": 1, "params": {}}]}, "seq.json")
    r = run("bake", "--sequence", seq, *extra, "--resolution", 16, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--sequence", extra[0])
    assert listing(out_dir) == []


def test_bake_key_metadata_differs_by_tier_and_resolution(out_dir):
    """Same params (cumulus, time 0): the field part of the key (before '-') is the module's
    field_key and is shared; the whole key differs between bakes that store different voxels.
    --quality final at 16 equals the plain --resolution 16 bake (tolerance 0, full floats, LOD)."""
    bakes = {
        "r16": ["--resolution", 16],
        "r24": ["--resolution", 24],
        "draft": ["--quality", "draft"],
        "draft16": ["--quality", "draft", "--resolution", 16],
        "preview16": ["--quality", "preview", "--resolution", 16],
        "final16": ["--quality", "final", "--resolution", 16],
        "r16nolod": ["--resolution", 16, "--no-lod"],
    }
    for name, args in bakes.items():
        r = run("bake", "--preset", "cumulus", *args, "--output", out_dir / f"{name}.vdb", "--quiet")
        assert r.returncode == 0, (name, r.stderr)
    keys = dict(zip(bakes, bake_keys([out_dir / f"{name}.vdb" for name in bakes])))
    # The reader agrees with `cloudgen info` (exact string), checked on one file.
    assert grid(out_dir / "r16.vdb")["metadata"]["cloudgen_bake_key"] == keys["r16"]
    fields = {k.split("-")[0] for k in keys.values()}
    assert len(fields) == 1, keys
    try:
        import cloudgen_native as cn
    except ImportError:
        cn = None
    if cn is not None:
        assert fields == {cn.field_key({"preset": "cumulus"})}, (keys, cn.field_key({"preset": "cumulus"}))
    assert keys["final16"] == keys["r16"], keys
    distinct = [keys[n] for n in ("r16", "r24", "draft", "draft16", "preview16", "r16nolod")]
    assert len(set(distinct)) == len(distinct), keys
