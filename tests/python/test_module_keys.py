"""cloudgen_native.tiers(), field_key() and density(..., footprint=).

Interfaces: the module's docstrings (help(cloudgen_native)). Every assertion states its tolerance;
failures print the parameters involved. Pure in-process: no CLI, no files written.
"""
import json
import math
import pathlib
import re

import cloudgen_native as cn
import numpy as np
import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
TIERS_FILE = REPO_ROOT / "native" / "presets" / "tiers.json"
CUMULUS = {"preset": "cumulus"}
STILL = {"preset": "cumulus", "evolution": 0.0, "wind_strength": 0.0}


def points(n=3000, seed=7, params=CUMULUS):
    """Random float32 points inside the box of params (local frame, centred)."""
    box = np.asarray(cn.resolve_params(params)["box_size"], dtype=np.float32)
    rng = np.random.default_rng(seed)
    return ((rng.random((n, 3), dtype=np.float32) - np.float32(0.5)) * box).astype(np.float32)


# ------------------------------------------------------------------ tiers ---

def test_tiers_is_the_data_file_in_order():
    # Tolerance: exact (parsed structure equal; key order of the file kept at every level).
    expected = json.loads(TIERS_FILE.read_text())
    got = cn.tiers()
    assert got == expected, (got, expected)
    assert list(got) == list(expected) == ["draft", "preview", "final"], list(got)
    assert json.dumps(got) == json.dumps(expected), "nested key order differs from the file"


def test_tiers_structure_and_fresh_copies():
    # Tolerance: exact (keys and types as documented in tiers()'s docstring).
    t = cn.tiers()
    for name, tier in t.items():
        assert {"label", "description", "render", "bake", "preview", "measured"} <= set(tier), (name, tier)
        assert set(tier["render"]) >= {"samples", "step_rate"}, (name, tier["render"])
        assert set(tier["bake"]) >= {"resolution", "lod", "tolerance", "half"}, (name, tier["bake"])
        assert isinstance(tier["bake"]["resolution"], int) and tier["bake"]["resolution"] >= 1, (name, tier)
        assert isinstance(tier["bake"]["lod"], bool) and isinstance(tier["bake"]["half"], bool), (name, tier)
        assert isinstance(tier["measured"], dict), (name, tier)
    # Tiers get finer: bake resolution and samples rise from draft to final.
    res = [t[n]["bake"]["resolution"] for n in ("draft", "preview", "final")]
    spp = [t[n]["render"]["samples"] for n in ("draft", "preview", "final")]
    assert res == sorted(res) and spp == sorted(spp), (res, spp)
    # Mutating the result does not change the next call (exact).
    t["draft"]["bake"]["resolution"] = -1
    del t["final"]
    assert cn.tiers() == json.loads(TIERS_FILE.read_text())


# -------------------------------------------------------------- field_key ---

HEX16 = re.compile(r"^[0-9a-f]{16}$")


@pytest.mark.parametrize("params", [{}, None, CUMULUS, STILL, {"preset": "cirrus", "seed": 12}],
                         ids=["empty", "None", "cumulus", "still", "cirrus"])
def test_field_key_is_16_hex_digits(params):
    k = cn.field_key(params)
    assert isinstance(k, str) and HEX16.match(k), (params, k)
    assert cn.field_key(params) == k, "deterministic"


def test_field_key_same_for_equal_spellings():
    # Exact: a preset name and its resolved values are the same parameters.
    assert cn.field_key(CUMULUS) == cn.field_key(cn.resolve_params(CUMULUS))
    assert cn.field_key({}) == cn.field_key(None) == cn.field_key(cn.defaults())


def test_field_key_drops_time_of_a_still_cloud():
    # Exact: no wind, no evolution -> time cannot change the field, so neither the key ...
    k0 = cn.field_key({**STILL, "time": 0.0})
    k10 = cn.field_key({**STILL, "time": 10.0})
    assert k0 == k10, (STILL, k0, k10)
    # ... nor the density (bit-identical at 3000 points): equal keys mean equal fields.
    p = points()
    assert np.array_equal(cn.density({**STILL, "time": 0.0}, p), cn.density({**STILL, "time": 10.0}, p))


@pytest.mark.parametrize("moving", [{"evolution": 0.1}, {"evolution": 2.0}, {"wind_strength": 1.0}],
                         ids=["evolution0.1", "evolution2", "wind"])
def test_field_key_keeps_time_of_a_moving_cloud(moving):
    # Exact: evolution or wind make time part of the field: keys and densities differ.
    params = {**STILL, **moving}
    k0, k10 = cn.field_key({**params, "time": 0.0}), cn.field_key({**params, "time": 10.0})
    assert k0 != k10, (params, k0)
    p = points()
    assert not np.array_equal(cn.density({**params, "time": 0.0}, p), cn.density({**params, "time": 10.0}, p)), \
        params


@pytest.mark.parametrize("change", [{"density": 0.6}, {"seed": 1}, {"noise_detail": 4.0}, {"noise_detail": 5.5},
                                    {"cloud_scale": 0.7}, {"box_size": [4.0, 4.0, 3.5]}],
                         ids=["density", "seed", "detail-int", "detail-frac", "cloud_scale", "box"])
def test_field_key_changes_with_the_field(change):
    # Exact: each change alters the field (checked on the density) and the key.
    base = cn.field_key(CUMULUS)
    changed = {**CUMULUS, **change}
    assert cn.field_key(changed) != base, (change, base)
    p = points(params=CUMULUS)
    assert not np.array_equal(cn.density(CUMULUS, p), cn.density(changed, p)), change


def test_field_key_ignores_what_the_field_ignores():
    # Exact: cumulus uses the shape curve (shape_mode 1), so shape_exponent cannot change
    # the field; the key may (and does) ignore it, and the densities are bit-identical.
    other = {**CUMULUS, "shape_exponent": 0.3}
    assert cn.resolve_params(CUMULUS)["shape_mode"] == 1
    p = points()
    assert np.array_equal(cn.density(CUMULUS, p), cn.density(other, p))
    assert cn.field_key(other) == cn.field_key(CUMULUS)


PAIRS = [  # (a, b): parameter sets whose fields may or may not be equal
    ({**STILL, "evolution": 0.1}, STILL),                       # time 0: evolution does nothing yet
    ({**STILL, "wind_direction": [0.0, 1.0, 0.0]}, STILL),      # no wind: direction does nothing
    ({**STILL, "wind_strength": 1.0}, STILL),                   # wind at time 0
    ({**STILL, "wind_strength": 1.0, "time": 1.0}, STILL),      # wind at time 1 moves the noise
    ({**STILL, "evolution": 0.5, "time": 0.0}, {**STILL, "time": 0.1}),
    ({**STILL, "evolution": 0.5, "time": 0.2}, {**STILL, "evolution": 0.1, "time": 1.0}),  # same evolution x time?
    ({**STILL, "object_location": [5.0, 0.0, 0.0]}, STILL),
    ({**STILL, "noise_whisp": 0.6}, STILL),
    ({**STILL, "density": 0.0}, {**STILL, "density": 0.0, "seed": 3}),  # both empty everywhere: one key
]


@pytest.mark.parametrize("a,b", PAIRS, ids=["evolution-at-t0", "wind-direction-without-wind", "wind-at-t0",
                                            "wind-at-t1", "evolution-vs-time-both-w0", "evolution-x-time",
                                            "object-location", "noise-whisp", "density-zero-seed"])
def test_equal_keys_iff_equal_densities(a, b):
    """field_key's contract: equal keys <=> equal density fields. The field equality is
    judged bit-exactly at 3000 random points (a difference anywhere would be missed only if
    the two fields agreed at all of them). A key that differs for equal fields is reported
    as conservative (not wrong for dedupe, but not "<=>")."""
    p = points()
    same_field = np.array_equal(cn.density(a, p), cn.density(b, p))
    same_key = cn.field_key(a) == cn.field_key(b)
    if same_key:
        assert same_field, f"equal keys for different fields: {a} vs {b}"
    else:
        assert not same_field, f"different keys for equal fields (time or inert parameters not dropped): {a} vs {b}"


@pytest.mark.parametrize("params,error,needle", [
    ({"densty": 1.0}, ValueError, "densty"),
    ({"density": 50}, ValueError, "density"),
    (5, TypeError, "params"),
])
def test_field_key_refuses_bad_params(params, error, needle):
    with pytest.raises(error) as info:
        cn.field_key(params)
    assert needle in str(info.value), (params, str(info.value))


# -------------------------------------------------------------- footprint ---

def test_footprint_zero_is_full_detail():
    # Exact (bit-identical): footprint 0 (int, float, -0.0) is the default; a footprint far
    # below the finest octave (1e-9 units) replaces no octave either.
    p = points()
    full = cn.density(CUMULUS, p)
    for f in (0, 0.0, -0.0, np.float32(0), 1e-9):
        got = cn.density(CUMULUS, p, footprint=f)
        assert np.array_equal(got, full), (f, float(np.abs(got - full).max()))


@pytest.mark.parametrize("footprint", [0.125, 1.0, 100.0])
def test_large_footprint_smooths_but_stays_valid(footprint):
    # Values differ from full detail (somewhere, exact comparison), stay finite and >= 0,
    # and points outside the box still give exactly 0.
    p = points()
    full = cn.density(CUMULUS, p)
    lod = cn.density(CUMULUS, p, footprint=footprint)
    assert lod.dtype == np.float32 and lod.shape == full.shape
    assert not np.array_equal(lod, full), footprint
    assert np.all(np.isfinite(lod)) and lod.min() >= 0.0, (footprint, float(lod.min()))
    outside = np.array([[2.5, 0, 0], [0, -2.5, 0], [0, 0, 1.6], [np.nan, 0, 0]], dtype=np.float32)
    assert np.array_equal(cn.density(CUMULUS, outside, footprint=footprint), np.zeros(4, np.float32))
    # Deterministic and thread-independent (exact).
    assert np.array_equal(cn.density(CUMULUS, p, footprint=footprint, threads=1), lod)


def test_footprint_changes_less_when_smaller():
    # The detail lost grows with the footprint: RMS difference to full detail at footprint
    # 0.01 < at 0.125 < at 1 (strict; measured 0.0016 < 0.1 < 0.5 roughly for cumulus).
    p = points()
    full = cn.density(CUMULUS, p).astype(np.float64)
    rms = [float(np.sqrt(np.mean((cn.density(CUMULUS, p, footprint=f) - full) ** 2))) for f in (0.01, 0.125, 1.0)]
    assert rms[0] < rms[1] < rms[2], rms


@pytest.mark.parametrize("footprint", [-1.0, -1e-30, float("nan"), -math.inf])
def test_bad_footprint_refused(footprint):
    with pytest.raises(ValueError) as info:
        cn.density(CUMULUS, np.zeros((2, 3)), footprint=footprint)
    assert "footprint" in str(info.value), (footprint, str(info.value))


@pytest.mark.parametrize("footprint", ["1", None, [0.5]])
def test_footprint_of_wrong_type_refused(footprint):
    with pytest.raises((TypeError, ValueError)) as info:
        cn.density(CUMULUS, np.zeros((2, 3)), footprint=footprint)
    assert "footprint" in str(info.value), (footprint, str(info.value))


def test_bake_plan_is_what_the_cli_plans(tmp_path):
    """cloudgen_native.bake_plan (used by the add-on's in-Blender bake) gives the grid, voxel
    and bake key `cloudgen bake --dry-run --json` plans, for a few settings. Exact."""
    import subprocess

    from test_cli import CLOUDGEN

    for params, res, flags, kw in [({"preset": "cumulus"}, 24, [], {}),
                                   ({"preset": "cirrus", "seed": 4}, 40, ["--no-lod", "--half"],
                                    {"lod": False, "half": True}),
                                   ({"preset": "stratus"}, 17, ["--tolerance", "0.25"], {"tolerance": 0.25})]:
        pfile = tmp_path / "p.json"
        pfile.write_text(json.dumps(params))
        r = subprocess.run([CLOUDGEN, "bake", "--params", str(pfile), "--resolution", str(res), *flags, "--dry-run",
                            "--json", "--output", str(tmp_path / "x.vdb")], capture_output=True, text=True, check=True)
        cli = json.loads(r.stdout.splitlines()[0])
        plan = cn.bake_plan(params, res, **kw)
        assert plan["grid"] == cli["grid"] and plan["key"] == cli["files"][0]["key"], (params, plan, cli)
        assert math.isclose(plan["voxel"], cli["voxel"], rel_tol=1e-7), (plan["voxel"], cli["voxel"])
        f = np.float32  # the core computes the origin in float32: -0.5f * n * voxel
        assert plan["origin"] == [float(f(-0.5) * f(n) * f(plan["voxel"])) for n in plan["grid"]], plan["origin"]
    with pytest.raises(ValueError, match="resolution"):
        cn.bake_plan({}, 0)
