"""Cloud Quality tiers in the add-on (addon/quality.py): the enum lists Custom and
exactly the core's tiers (cloudgen_native.tiers(), in order), applying a tier
sets the real settings (Cycles samples, volume step rate, preview size, the
bake's resolution and flags), tooltips carry the measured numbers (or say
"not measured yet"), settings changed by hand are listed, and the bake
arguments pass --quality plus only explicit overrides."""
import pytest
from test_ui_draw import draw


@pytest.fixture
def tiers(addon):
    if not hasattr(addon.bridge.native(), "tiers"):
        pytest.skip("this cloudgen_native has no tiers() yet")
    return addon.bridge.tiers()


def _enum_items(scene):
    # dynamic items: ask the callback (bl_rna's enum_items of a dynamic enum is empty)
    from cloudgen import quality

    return quality.tier_items(scene.cloudgen, None)


def test_enum_lists_custom_then_the_core_tiers(addon, scene, tiers):
    items = _enum_items(scene)
    assert [i[0] for i in items] == ["CUSTOM"] + list(tiers)
    assert [i[1] for i in items[1:]] == [t["label"] for t in tiers.values()]
    assert scene.cloudgen.quality == "CUSTOM"  # a new scene: nothing applied
    for ident, _, _ in items:
        scene.cloudgen.quality = ident  # every identifier is accepted by the real property
        assert scene.cloudgen.quality == ident


@pytest.mark.parametrize("name", ["draft", "preview", "final"])
def test_apply_sets_the_real_settings(addon, scene, tiers, name):
    import bpy

    if name not in tiers:
        pytest.skip(f"no tier {name!r} in this core")
    tier = tiers[name]
    scene.cycles.samples = 3
    scene.cycles.volume_step_rate = 7.0
    assert bpy.ops.cloudgen.apply_quality(tier=name) == {"FINISHED"}
    assert scene.cloudgen.quality == name
    assert scene.cycles.samples == tier["render"]["samples"]
    assert scene.cycles.volume_step_rate == pytest.approx(tier["render"]["step_rate"], rel=1e-6)
    assert scene.cloudgen.preview_width == min(512, max(16, tier["preview"]["size"]))
    assert addon.quality.drift(scene) == []
    # the bake: --quality NAME and nothing else without overrides; the tier's values
    # explicitly when it cannot go by name
    res, extra = addon.quality.bake_arguments(*addon.quality.current(scene)[:1], tier["bake"], {})
    assert (res, extra) == (None, ["--quality", name])
    res, extra = addon.quality.bake_arguments(None, tier["bake"], {})
    b = tier["bake"]
    assert res == b["resolution"]
    assert ("--half" in extra) == b["half"] and ("--no-lod" in extra) == (not b["lod"])
    assert ("--tolerance" in extra) == (b["tolerance"] != 0)
    if b["tolerance"]:
        assert float(extra[extra.index("--tolerance") + 1]) == pytest.approx(b["tolerance"], rel=1e-12)


def test_choosing_in_the_enum_applies_and_hand_changes_are_listed(addon, scene, tiers):
    name, tier = next(iter(tiers.items()))
    scene.cloudgen.quality = name  # as the dropdown does
    assert scene.cycles.samples == tier["render"]["samples"]
    scene.cycles.samples = tier["render"]["samples"] + 5
    changed = addon.quality.drift(scene)
    assert len(changed) == 1 and changed[0].startswith(f"Samples {tier['render']['samples'] + 5} ")
    log = draw(addon.quality.CLOUDGEN_PT_quality, __import__("bpy").context)
    assert ("prop", "") in log and ("operator", "cloudgen.apply_quality") in log
    assert any(k == "label" and t.startswith("Changed by hand: Samples") for k, t in log)
    scene.cloudgen.quality = "CUSTOM"  # Custom changes nothing
    assert scene.cycles.samples == tier["render"]["samples"] + 5
    assert addon.quality.drift(scene) == []


def test_tooltips_show_measured_numbers(addon, scene, monkeypatch):
    fake = {
        "draft": {"label": "Draft", "description": "Fast.", "render": {"samples": 16, "step_rate": 2.0},
                  "bake": {"resolution": 64, "lod": True, "tolerance": 0.01, "half": True},
                  "preview": {"size": 128},
                  "measured": {"cumulus": {"render_s": 3.21, "bake_s": 0.4, "rmse": 0.0042,
                                           "flip": 0.0312, "field_rms": 0.01}}},
        "final": {"label": "Final", "description": "", "render": {"samples": 256},
                  "bake": {"resolution": 256}, "preview": {"size": 512}, "measured": {}},
    }
    monkeypatch.setattr(addon.bridge, "tiers", lambda: fake)
    items = {i[0]: i for i in addon.quality.tier_items(scene.cloudgen, None)}
    assert list(items) == ["CUSTOM", "draft", "final"]
    tip = items["draft"][2]
    assert "cumulus: render 3.2 s, bake 0.40 s, slight grain" in tip   # time and look, no FLIP/RMSE
    assert "FLIP" not in tip and "RMSE" not in tip
    assert "16 samples" in tip and "bake 64³ half" in tip
    assert items["final"][2].endswith("Measured: not measured yet")
    scene.cloudgen.quality = "draft"
    log = draw(addon.quality.CLOUDGEN_PT_quality, __import__("bpy").context)
    text = " ".join(t for kind, t in log if kind == "label")
    assert "cumulus: render 3.2 s, bake 0.40 s, slight grain" in text, log


def test_overrides_and_unexpressible_overrides(addon):
    q = addon.quality
    bake = {"resolution": 64, "lod": True, "tolerance": 0.01, "half": True}
    assert q.bake_arguments("draft", bake, {"resolution": 24}) == (24, ["--quality", "draft"])
    assert q.bake_arguments("draft", bake, {"lod": False, "tolerance": 0.5}) == \
        (None, ["--quality", "draft", "--tolerance", "0.5", "--no-lod"])
    # full floats against a half-float tier: no flag says that, so everything explicitly
    assert q.bake_arguments("draft", bake, {"half": False}) == (64, ["--tolerance", "0.01"])
    # Custom: the operator's own defaults, as before tiers existed
    assert q.bake_arguments(None, None, {}) == (96, [])
    assert q.bake_arguments(None, None, {"lod": False, "resolution": 8}) == (8, ["--no-lod"])


def test_without_tiers_only_custom(addon, scene, monkeypatch):
    import bpy

    def missing():
        raise RuntimeError("this cloudgen_native has no quality tiers (tiers()): update the add-on")

    monkeypatch.setattr(addon.bridge, "tiers", missing)
    assert [i[0] for i in addon.quality.tier_items(scene.cloudgen, None)] == ["CUSTOM"]
    with pytest.raises(TypeError, match="\"draft\" not found in \\('CUSTOM'\\)"):
        bpy.ops.cloudgen.apply_quality(tier="draft")  # Blender's own check of the enum
    with pytest.raises(KeyError, match="unknown quality tier 'draft'.*no quality tiers"):
        addon.quality.apply(scene, "draft")
    log = draw(addon.quality.CLOUDGEN_PT_quality, bpy.context)
    text = " ".join(t for kind, t in log if kind == "label")
    assert "this cloudgen_native has no quality tiers (tiers()): update the add-on" in text, log


def test_bake_panel_shows_fit_to_camera_and_the_tier(addon, scene, tiers):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    log = draw(addon.bake_panel.CLOUDGEN_PT_bake, bpy.context)
    assert ("prop", "bake_fit_camera") in log
    assert ("label", "Custom: 96³") in log
    name, tier = next(iter(tiers.items()))
    bpy.ops.cloudgen.apply_quality(tier=name)
    log = draw(addon.bake_panel.CLOUDGEN_PT_bake, bpy.context)
    summary = [t for k, t in log if k == "label" and t.startswith(tier["label"] + ": ")]
    assert summary and summary[0].startswith(f"{tier['label']}: {tier['bake']['resolution']}³")
