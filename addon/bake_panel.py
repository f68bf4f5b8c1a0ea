"""The Bake panel (sidebar tab Cloud): Bake Frame / Bake Frame Range, Fit to Camera,
the tier's bake settings, the procedural/baked switch, the baked file, and
"Stale" when the cloud's parameters no longer give the field it was baked from
(the bake record's field keys, checks.stale), and why (checks.stale_reason)."""
import bpy

from . import bake, checks, cloud_object, quality, volume_object
from .panel import SidebarPanel, wrapped_label


class CLOUDGEN_PT_bake(SidebarPanel, bpy.types.Panel):
    bl_label = "Bake"
    bl_idname = "CLOUDGEN_PT_bake"
    bl_parent_id = "CLOUDGEN_PT_main"

    @classmethod
    def poll(cls, context):
        return cloud_object.is_cloud(context.view_layer.objects.active)

    def draw(self, context):
        layout = self.layout
        cloud = context.view_layer.objects.active
        col = layout.column(align=True)
        op = col.operator(bake.CLOUDGEN_OT_bake_vdb.bl_idname, text="Bake Frame", icon="FILE_VOLUME")
        op.sequence = False
        op = col.operator(bake.CLOUDGEN_OT_bake_vdb.bl_idname, text="Bake Frame Range", icon="SEQUENCE")
        op.sequence = True
        row = layout.row()
        row.prop(context.scene.cloudgen, "bake_fit_camera")
        wrapped_label(layout, quality.bake_summary(context.scene), "SETTINGS", context)
        source = cloud.get(volume_object.SOURCE_KEY, "PROCEDURAL")
        baked = volume_object.baked_object(cloud)
        row = layout.row(align=True)
        for key, label in (("PROCEDURAL", "Procedural"), ("BAKED", "Baked")):
            sub = row.row(align=True)
            sub.enabled = key == "PROCEDURAL" or baked is not None
            op = sub.operator(bake.CLOUDGEN_OT_cloud_source.bl_idname, text=label, depress=source == key)
            op.source = key
        if baked is not None:
            layout.label(text=baked.name, icon="OUTLINER_DATA_VOLUME")
            layout.label(text=bpy.path.basename(baked.data.filepath) or "(no file)", icon="FILE")
            why = checks.stale_reason(cloud, context.scene)
            if why is not None:
                layout.label(text=f"Stale: {checks.STALE_REASONS[why][0]}", icon="ERROR")
        if not bpy.data.filepath:
            wrapped_label(layout, "Save the .blend first (output is //cloudgen/)", "INFO", context)


classes = (CLOUDGEN_PT_bake,)
