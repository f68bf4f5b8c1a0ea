"""Register/unregister: 20 cycles in one process, nothing left behind."""


def _leftovers():
    import bpy

    out = []
    out += [n for n in dir(bpy.types) if n.startswith(("CLOUDGEN_", "CloudgenScene"))]
    if hasattr(bpy.types.Scene, "cloudgen"):
        out.append("Scene.cloudgen")
    for handlers in (bpy.app.handlers.depsgraph_update_post,):
        out += [f"handler {h.__module__}.{h.__name__}" for h in handlers
                if h.__module__.startswith("cloudgen")]
    for menu in ("VIEW3D_MT_volume_add", "VIEW3D_MT_mesh_add"):
        funcs = getattr(getattr(bpy.types, menu).draw, "_draw_funcs", [])
        out += [f"{menu} draws {f.__module__}.{f.__name__}" for f in funcs
                if getattr(f, "__module__", "").startswith("cloudgen")]
    return out


def test_register_unregister_20_times(package):
    import addon_utils
    import bpy

    def fail(exc):
        raise exc

    assert _leftovers() == []
    for i in range(20):
        mod = addon_utils.enable("cloudgen", default_set=False, handle_error=fail)
        assert mod is not None
        assert hasattr(bpy.types, "CLOUDGEN_OT_add_cloud") and hasattr(bpy.types.Scene, "cloudgen")
        assert mod.preview.on_depsgraph_update in bpy.app.handlers.depsgraph_update_post
        assert hasattr(bpy.ops.cloudgen, "add_cloud")
        addon_utils.disable("cloudgen", default_set=False, handle_error=fail)
        assert _leftovers() == [], f"after cycle {i + 1}"
    assert mod.preview.state.previews is None  # preview collection freed


def test_menus_and_panels_registered(addon):
    import bpy

    for menu in ("VIEW3D_MT_volume_add", "VIEW3D_MT_mesh_add"):
        funcs = getattr(bpy.types, menu).draw._draw_funcs
        assert addon.operators.menu_add in funcs
    for cls in addon.ui.classes:
        assert cls.bl_category == "Cloud" and cls.bl_region_type == "UI"
        assert getattr(bpy.types, cls.bl_idname).is_registered


def test_every_module_in_one_tuple(addon):
    """The contract with the bake operator: registration walks addon._modules."""
    registered = [cls for m in addon._modules for cls in m.classes]
    assert set(registered) == set(addon._registered)
