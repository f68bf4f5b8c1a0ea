"""The camera-aware bake (`bake --camera`, docs/camera.md): voxel = pixel footprint at the
nearest visible depth, caps, margins, culling, bad camera files. Voxel values are read back
with the openvdb module of the bpy wheel (tests/vdb_voxels.py). Every assertion states its
tolerance; failures print the inputs."""

import numpy as np
import pytest
from cli_bake_helpers import (
    CUMULUS_4X4,
    CUMULUS_BOX,
    CUMULUS_DENSITY,
    LONGEST,
    NARROW,
    camera_lines,
    cumulus_args,
    grid,
    looking_along_y,
    run,
)
from test_cli import expect_usage_error, listing
from vdb_voxels import read_voxels

# ----------------------------------------------------------------- camera ---

# (tan_half_fov, resolution): footprint = 2 * depth * min(tx / w, ty / h), depth 6 in both;
# the first is limited by both axes equally, the second by the vertical one.
FOV_CASES = [([0.36, 0.27], [40, 30]), ([0.5, 0.27], [40, 30])]


@pytest.mark.parametrize("fov,res", FOV_CASES, ids=["square-pixels", "vertical-limits"])
def test_camera_voxel_is_the_pixel_footprint_at_the_nearest_depth(fov, res, inputs, out_dir):
    cam = {"camera_to_cloud": looking_along_y(-8.0), "tan_half_fov": fov, "resolution": res}
    out = out_dir / "cam.vdb"
    r = run("bake", *cumulus_args(out_dir), "--camera", inputs(cam), "--output", out)
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit is not None, r.stdout
    depth, footprint, fit_voxel, margin = fit
    # Hand computation: the eye at y=-8, the front face of the 4x4x2.4 box at y=-2 (inside the
    # view: half width 0.36*6 > 2, half height 0.27*6 > 1.2) -> depth 6.
    expected_depth = 6.0
    expected_fp = 2 * expected_depth * min(fov[0] / res[0], fov[1] / res[1])
    # Default margin (camera.h): 16 / peak extinction, extinction = Density x 20 per unit,
    # at most the longest side (the cumulus: min(16 / (0.8 * 20), 4) = 1.0).
    rel = 1e-3  # the lines print 6 significant digits; float32 arithmetic inside
    assert depth == pytest.approx(expected_depth, rel=rel), (cam, r.stdout)
    assert footprint == pytest.approx(expected_fp, rel=rel), (cam, r.stdout)
    assert fit_voxel == pytest.approx(expected_fp, rel=rel) and voxel == pytest.approx(expected_fp, rel=rel)
    assert margin == pytest.approx(min(16 / (CUMULUS_DENSITY * 20), LONGEST), rel=rel), r.stdout
    assert 0 < visible <= total
    g = grid(out)
    assert g["voxel_size"] == pytest.approx([expected_fp] * 3, rel=rel), (cam, g["voxel_size"])
    assert g["active_voxels"] > 0


def test_camera_pixels_per_voxel_and_margin(inputs, out_dir):
    base = {"camera_to_cloud": looking_along_y(-8.0), "tan_half_fov": [0.36, 0.27], "resolution": [40, 30]}
    r1 = run("bake", *cumulus_args(out_dir), "--camera", inputs(base, "a.json"), "--output", out_dir / "a.vdb")
    r2 = run("bake", *cumulus_args(out_dir), "--camera", inputs({**base, "pixels_per_voxel": 2, "margin": 0.5},
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
        r = run("bake", *cumulus_args(out_dir), "--camera", cam, "--resolution", cap, "--output", out)
        _, (voxel, _, _) = camera_lines(r)
        g = grid(out)
        assert g["voxel_size"][0] >= LONGEST / cap * (1 - 1e-6), (cap, g["voxel_size"])
        assert g["voxel_size"][0] == pytest.approx(expected, rel=1e-6), (cap, g["voxel_size"], r.stdout)
        assert voxel == pytest.approx(expected, rel=1e-3), (cap, r.stdout)


def test_camera_inside_the_box_needs_the_cap(inputs, out_dir):
    # Eye at the box centre: nearest depth = near clip 0.5, voxel 2*0.5*0.009 = 0.009,
    # ~445x445x334 voxels -> refused by a 0.05 GiB memory budget naming --camera; capped it bakes.
    # Density 0.8, not the preset's (denser): the denser cloud hides more of itself from an eye
    # inside it, and at 2.4 the bake culled 89 % of the tiles (94,754 of 106,624) and planned 3 MB.
    cam = inputs({"camera_to_cloud": looking_along_y(0.0), "tan_half_fov": [0.36, 0.27], "resolution": [40, 30],
                  "near": 0.5})
    thin = inputs({"preset": "cumulus", "density": 0.8}, "thin.json")
    r = run("bake", "--params", thin, "--camera", cam, "--max-memory", 0.05, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", "GiB", "--max-memory")
    assert listing(out_dir) == []
    r = run("bake", *cumulus_args(out_dir), "--camera", cam, "--resolution", 32, "--output", out_dir / "x.vdb")
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit is not None and fit[0] == pytest.approx(0.5, rel=1e-3), r.stdout  # depth = near clip
    assert voxel == pytest.approx(LONGEST / 32, rel=1e-3), r.stdout


def test_camera_looking_away_bakes_an_empty_file(inputs, out_dir):
    cam = inputs({"camera_to_cloud": looking_along_y(-8.0, sign=-1), "tan_half_fov": [0.36, 0.27],
                  "resolution": [40, 30]})
    out = out_dir / "away.vdb"
    r = run("bake", *cumulus_args(out_dir), "--camera", cam, "--output", out)
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
    r = run("bake", *cumulus_args(out_dir), "--camera", inputs(NARROW), "--output", cam_out)
    fit, (voxel, visible, total) = camera_lines(r)
    assert fit[0] == 4.0 and voxel == 0.125, r.stdout  # exact (printed %g of exact binary values)
    assert 0 < visible < total, r.stdout
    r = run("bake", *cumulus_args(out_dir), "--resolution", 32, "--output", uni_out, "--quiet")
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
    # (centre = (i,j,k)*voxel + origin + voxel/2, float32, as `cloudgen bake --help` says); a
    # cell overhanging the box at the centre of its part inside the box, times the part's share
    # of the cell (float32, per axis: the part [max(lo, -B/2), min(hi, B/2)]).
    cn = pytest.importorskip("cloudgen_native")
    out = out_dir / "u.vdb"
    r = run("bake", *cumulus_args(out_dir), "--resolution", 32, "--output", out, "--quiet")
    assert r.returncode == 0, r.stderr
    vox, _, _ = read_voxels(out)
    coords = np.array(sorted(vox), dtype=np.float32)
    values = np.array([vox[tuple(int(v) for v in c)] for c in coords], dtype=np.float32)
    v = np.float32(LONGEST / 32)
    # the grid is centred on the box and may overhang a shorter side by less than a voxel:
    # n = ceil(box / voxel - 1e-4) voxels per axis (grid_for_voxel), origin -n * voxel / 2
    n = np.ceil(np.array(CUMULUS_BOX, dtype=np.float64) / float(v) - 1e-4).astype(np.float32)
    corner = np.float32(-0.5) * n * v
    centres = (coords * v + corner + v / np.float32(2)).astype(np.float32)
    half = np.float32(0.5) * np.array(CUMULUS_BOX, dtype=np.float32)
    lo, hi = centres - np.float32(0.5) * v, centres + np.float32(0.5) * v
    part_lo, part_hi = np.maximum(lo, -half), np.minimum(hi, half)
    clipped = (lo < -half) | (hi > half)
    points = np.where(clipped, part_lo + np.float32(0.5) * (part_hi - part_lo), centres).astype(np.float32)
    fraction = np.where(clipped, (part_hi - part_lo) / v, np.float32(1)).astype(np.float32)
    share = fraction[:, 0] * fraction[:, 1] * fraction[:, 2]
    got = cn.density(CUMULUS_4X4, points, footprint=float(v)) * share
    assert np.any(clipped), "no cell overhangs the box: the rule is not tested"
    bad = np.flatnonzero(got != values)
    assert bad.size == 0, [(coords[i].tolist(), float(values[i]), float(got[i])) for i in bad[:5]]


def test_light_directions_keep_more_tiles(inputs, out_dir):
    # margin 0: without lights only the view frustum; with a sun above and to the side the
    # frustum is swept towards it (shadow casters kept). Exact counts compared.
    r0 = run("bake", *cumulus_args(out_dir), "--camera", inputs(NARROW, "n0.json"), "--output", out_dir / "n0.vdb")
    lit = {**NARROW, "light_directions": [[0.3, 0.2, 1.0]]}
    r1 = run("bake", *cumulus_args(out_dir), "--camera", inputs(lit, "n1.json"), "--output", out_dir / "n1.vdb")
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
    r = run("bake", *cumulus_args(out_dir), "--camera", path, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", *words)
    assert listing(out_dir) == []


def test_missing_camera_file(out_dir):
    r = run("bake", *cumulus_args(out_dir), "--camera", out_dir / "nope.json", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--camera", "nope.json")
    assert listing(out_dir) == []


