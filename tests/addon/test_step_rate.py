"""Cloud Render Settings keeps each cloud type's procedural step rate (its preset's material:
0.1 for the dense cumulus, whose coarser steps measured 11 % too bright against its bake in
tests/addon_bake/test_baked_vs_procedural.py; 0.5 for thin ice clouds) unless the artist
gives one. Until 2026-11 it set 0.2 on every cloud. Exact comparisons at float32."""
import pytest


def test_render_settings_keep_each_types_step_rate(addon, scene):
    import bpy

    presets = addon.bridge.presets()
    clouds = {}
    for kind in ("cumulus", "cirrus", "stratus"):
        assert bpy.ops.cloudgen.add_cloud(cloud_type=kind) == {"FINISHED"}
        clouds[kind] = bpy.context.view_layer.objects.active
    want = {k: addon.volume_material.procedural_step_rate(presets[k].get("material", {})) for k in clouds}
    assert want["cumulus"] < want["stratus"] < want["cirrus"], want  # the test can tell them apart

    def rates():
        return {k: addon.cloud_object.cloud_material(o).cycles.volume_step_rate for k, o in clouds.items()}

    assert rates() == pytest.approx(want, rel=1e-6), "Add Cloud: the preset's step rate"
    assert bpy.ops.cloudgen.render_settings(denoise=False) == {"FINISHED"}
    assert rates() == pytest.approx(want, rel=1e-6), "Render Settings must keep each type's own"
    assert bpy.ops.cloudgen.render_settings(denoise=False, step_rate=0.3) == {"FINISHED"}
    assert rates() == pytest.approx({k: 0.3 for k in clouds}, rel=1e-6), "an explicit rate applies to all"
