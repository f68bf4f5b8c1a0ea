"""Clear reports instead of crashes: the native module missing, values out of range,
an active object that is not a cloud."""
import pytest


@pytest.fixture
def no_native(addon, monkeypatch):
    """The add-on as it registers when cloudgen_native cannot be loaded."""
    import addon_utils

    addon_utils.disable("cloudgen", default_set=False)
    monkeypatch.setenv("CLOUDGEN_ADDON_NO_NATIVE", "1")
    addon.bridge.reload()
    mod = addon_utils.enable("cloudgen", default_set=False)
    assert mod is not None
    yield mod
    addon_utils.disable("cloudgen", default_set=False)
    monkeypatch.delenv("CLOUDGEN_ADDON_NO_NATIVE")
    addon.bridge.reload()
    assert addon_utils.enable("cloudgen", default_set=False) is not None


def test_missing_native_module(no_native):
    import bpy

    bridge = no_native.bridge
    assert bridge.native() is None and "cloudgen_native" in bridge.error()
    lines = no_native.ui.status_lines(bpy.context)
    assert lines[0] == ("ERROR", bridge.error()) and "\n" not in bridge.error()
    # the cloud types are still listed (the shipped JSON), Add Cloud says what is wrong
    assert "cumulus" in bridge.presets()
    with pytest.raises(RuntimeError, match="Add Cloud: cloudgen_native disabled"):
        bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    with pytest.raises(RuntimeError, match="Preview: .*cloudgen_native"):
        bpy.ops.cloudgen.refresh_preview()
    bpy.context.view_layer.update()  # the depsgraph handler stays quiet


def test_real_import_failure_is_one_line(addon, tmp_path, monkeypatch):
    """A broken lib/ file and no module on sys.path: the error names both attempts."""
    bridge = addon.bridge
    bad = tmp_path / "lib"
    bad.mkdir()
    (bad / "cloudgen_native.abi3.so").write_bytes(b"not an ELF file")
    monkeypatch.setattr(bridge, "LIB_DIR", bad)
    monkeypatch.setitem(__import__("sys").modules, "cloudgen_native", None)  # import fails
    try:
        bridge.reload()
        err = bridge.error()
        assert err and "\n" not in err and "cloudgen_native.abi3.so" in err and "import cloudgen_native" in err
    finally:
        monkeypatch.undo()
        bridge.reload()
    assert bridge.native() is not None


def test_value_beyond_range_is_reported_on_preview(addon, scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    obj = bpy.context.view_layer.objects.active
    main, noise = addon.cloud_object.cloud_nodes(obj)
    main.inputs["Density"].default_value = 50.0  # a group socket's limits are soft: Python gets past
    with pytest.raises(RuntimeError, match=r"parameter 'density' must be a number in \[0, 10\]; got 50"):
        bpy.ops.cloudgen.refresh_preview()
    assert "density" in addon.preview.state.error
    main.inputs["Density"].default_value = 0.5
    noise.inputs["Noise Detail"].default_value = 99.0
    with pytest.raises(RuntimeError, match="noise_detail"):
        bpy.ops.cloudgen.refresh_preview()
    noise.inputs["Noise Detail"].default_value = 5.0
    assert bpy.ops.cloudgen.refresh_preview() == {"FINISHED"} and addon.preview.state.error is None


def test_not_a_cloud(addon, scene):
    import bpy

    cube = bpy.data.objects.new("Plain", bpy.data.meshes.new("Plain"))
    scene.collection.objects.link(cube)
    bpy.context.view_layer.objects.active = cube
    with pytest.raises(RuntimeError, match="not a cloud"):
        bpy.ops.cloudgen.refresh_preview()
    with pytest.raises(RuntimeError, match="not a cloud"):
        bpy.ops.cloudgen.time_from_frame()


def test_osl_status_lines(addon, scene):
    import bpy

    assert addon.ui.status_lines(bpy.context) == []  # Cycles, CPU, OSL on
    scene.cycles.shading_system = False
    (icon, text), = addon.ui.status_lines(bpy.context)
    assert "Open Shading Language is off" in text and "baked VDB" in text
    scene.cycles.shading_system = True
    scene.render.engine = "BLENDER_WORKBENCH"
    assert "Workbench" in addon.ui.status_lines(bpy.context)[0][1]
    scene.render.engine = "CYCLES"
    scene.cycles.device = "GPU"  # no OptiX on this machine
    assert "OSL needs the CPU or OptiX" in addon.ui.status_lines(bpy.context)[0][1]
    bpy.ops.cloudgen.render_settings()
    assert scene.cycles.device == "CPU" and scene.cycles.shading_system and scene.cycles.use_denoising
