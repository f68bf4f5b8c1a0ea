"""Scene settings of the add-on: scene.cloudgen (cloud type to add, preview options,
Cloud Quality tier, bake options)."""
import bpy

from . import bridge, quality

_type_items = []  # Blender needs the enum strings kept alive (dynamic items)


def cloud_type_items(self, context):
    global _type_items
    presets = bridge.presets()
    _type_items = [(name, name.replace("_", " ").title(), str(p.get("description", "")))
                   for name, p in presets.items()] or [("NONE", "No cloud types", bridge.error() or "")]
    return _type_items


def _preview_changed(self, context):
    from . import preview  # noqa: PLC0415

    if self.preview_live and bridge.native() is not None:
        preview.refresh(context)


def _proxy_changed(self, context):
    from . import proxy  # noqa: PLC0415

    proxy.on_toggle(self.id_data)


def _proxy_resolution_changed(self, context):
    from . import proxy  # noqa: PLC0415

    proxy.on_resolution(self.id_data)


class CloudgenSceneSettings(bpy.types.PropertyGroup):
    cloud_type: bpy.props.EnumProperty(name="Cloud Type", items=cloud_type_items,
                                       description="Type of cloud Add Cloud creates")
    preview_axis: bpy.props.EnumProperty(
        name="Axis", default="Y", update=_preview_changed,
        items=[("X", "X", "Cut perpendicular to X (looking along X)"),
               ("Y", "Y", "Cut perpendicular to Y (front view)"),
               ("Z", "Z", "Cut perpendicular to Z (top view)")])
    preview_offset: bpy.props.FloatProperty(
        name="Offset", min=0.0, max=1.0, default=0.5, subtype="FACTOR", update=_preview_changed,
        description="Position of the cut through the box (0 one face, 1 the opposite one)")
    preview_width: bpy.props.IntProperty(name="Resolution", min=16, max=512, default=128,
                                         update=_preview_changed,
                                         description="Width of the preview in pixels")
    preview_live: bpy.props.BoolProperty(name="Live", default=True,
                                         description="Update the preview when parameters change")
    proxy: bpy.props.BoolProperty(
        name="3D Proxy", default=True, update=_proxy_changed,
        description="Show a low-resolution volume of each cloud in the viewport (Solid, Eevee, "
                    "Cycles on a GPU), updated as you edit; never rendered")
    proxy_resolution: bpy.props.IntProperty(
        name="Voxels", min=32, max=128, default=64, update=_proxy_resolution_changed,
        description="Voxels of the 3D proxy along the cloud's longest side (more: finer and slower)")
    quality: bpy.props.EnumProperty(
        name="Cloud Quality", items=quality.tier_items, default=0, update=quality.on_quality_changed,
        description="Quality tier: render samples and step rate, preview size and bake settings "
                    "(Custom: your own settings)")
    bake_fit_camera: bpy.props.BoolProperty(
        name="Fit to Camera", default=False,
        description="Bake only what the scene camera sees, with voxels as small as a pixel at "
                    "the nearest visible point (perspective cameras; Bake to VDB's resolution "
                    "then caps the voxel count)")


classes = (CloudgenSceneSettings,)


def on_register():
    bpy.types.Scene.cloudgen = bpy.props.PointerProperty(type=CloudgenSceneSettings)


def on_unregister():
    if hasattr(bpy.types.Scene, "cloudgen"):
        del bpy.types.Scene.cloudgen
