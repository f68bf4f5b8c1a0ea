"""`cloudgen tiers`, `bake --quality` and the `cloudgen_bake_key` metadata. Every assertion
states its tolerance; failures print the inputs. No test asserts how long anything takes."""
import json

import pytest
from cli_bake_helpers import (
    CUMULUS_4X4,
    LONGEST,
    TIERS_FILE,
    bake_keys,
    cumulus_args,
    grid,
    run,
)
from test_cli import expect_usage_error, listing

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
    r = run("bake", *cumulus_args(out_dir), "--quality", "draft", "--output", out)
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
    # the cumulus with the thesis's linear edge (Edge Sharpness 0) and density 0.8: its faint rim (values
    # below the draft tolerance) is what --tolerance 0 must keep; the preset's sharp edge leaves almost
    # none at 16 voxels, and at the preset's (denser) density no sampled rim value falls below the tolerance
    soft = out_dir / "soft_cumulus.json"
    soft.write_text(json.dumps(dict(CUMULUS_4X4, edge_sharpness=0.0, density=0.8)))
    out = out_dir / "d16.vdb"
    r = run("bake", "--params", soft, "--quality", "draft", "--resolution", 16, "--output", out, "--quiet")
    assert r.returncode == 0, r.stderr
    g = grid(out)
    # --resolution wins (tolerance 1e-9 relative); half and the drop tolerance still come from the tier.
    assert g["voxel_size"] == pytest.approx([LONGEST / 16] * 3, rel=1e-9), g["voxel_size"]
    assert g["half"] is True and g["min"] > tier["tolerance"], g
    # The same bake spelled out has the same bake key (exact string).
    out2 = out_dir / "explicit.vdb"
    r = run("bake", "--params", soft, "--resolution", 16, "--half", "--tolerance", tier["tolerance"],
            "--output", out2, "--quiet")
    assert r.returncode == 0, r.stderr
    assert grid(out2)["metadata"]["cloudgen_bake_key"] == g["metadata"]["cloudgen_bake_key"]
    # --tolerance 0 wins too: the faint edge of the cumulus (values below 0.01) is kept.
    out3 = out_dir / "tol0.vdb"
    r = run("bake", "--params", soft, "--quality", "draft", "--resolution", 16, "--tolerance", 0,
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

