"""cloudgen — procedural volumetric clouds (Cloud Main / Cloud Noise node groups,
cloud types, live cross-section preview). Registration only; see README.md.

Installs as a legacy add-on (bl_info, Blender 3.4+) and as an extension
(blender_manifest.toml, 4.2+): relative imports only."""

bl_info = {
    "name": "cloudgen",
    "author": "cloudgen authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Add > Volume > Cloud; View3D > Sidebar > Cloud",
    "description": "Procedural volumetric clouds: node groups, cloud types, live preview",
    "category": "Add Mesh",
    # placeholder project address (no public home yet): replace when published
    "doc_url": "https://example.org/cloudgen",
    "tracker_url": "https://example.org/cloudgen/issues",
}

from . import (  # noqa: E402
    bake,
    bake_panel,
    bridge,
    checks,
    light_setup,
    operators,
    prefs,
    preview,
    props,
    proxy,
    proxy_panel,
    quality,
    ui,
)

# Each module has `classes` (registered in order) and may have on_register /
# on_unregister. Adding a module is one entry here.
# proxy_panel, quality and bake_panel after ui: their panels' parent is CLOUDGEN_PT_main
_modules = (prefs, props, operators, light_setup, preview, ui, proxy_panel, quality, bake, bake_panel, checks, proxy)

_registered = []


def register():
    bridge.native()  # load (or record why not) once, before any panel draws
    for mod in _modules:
        for cls in mod.classes:
            bpy_register(cls)
        if hasattr(mod, "on_register"):
            mod.on_register()


def unregister():
    for mod in reversed(_modules):
        if hasattr(mod, "on_unregister"):
            mod.on_unregister()
    while _registered:
        cls = _registered.pop()
        import bpy  # noqa: PLC0415

        if getattr(cls, "is_registered", False):
            bpy.utils.unregister_class(cls)


def bpy_register(cls):
    import bpy  # noqa: PLC0415

    bpy.utils.register_class(cls)
    _registered.append(cls)
