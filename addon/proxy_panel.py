"""The "3D Proxy" sub-panel of the Cloud tab (proxy.py does the work): the toggle,
the resolution, and for the active cloud how long its last refresh took (a warning
above proxy.SLOW_MS) or why there is no proxy."""
import bpy

from . import cloud_object, operators, proxy
from .panel import SidebarPanel, wrapped_label


class CLOUDGEN_PT_proxy(SidebarPanel, bpy.types.Panel):
    bl_label = "3D Proxy"
    bl_idname = "CLOUDGEN_PT_proxy"
    bl_parent_id = "CLOUDGEN_PT_main"

    def draw_header(self, context):
        self.layout.prop(context.scene.cloudgen, "proxy", text="")

    def draw(self, context):
        layout = self.layout
        s = context.scene.cloudgen
        row = layout.row()
        row.active = s.proxy
        row.prop(s, "proxy_resolution")
        if not s.proxy:
            return
        obj = context.view_layer.objects.active
        if cloud_object.is_cloud(obj):
            for icon, text in proxy.status(obj, context.scene):
                wrapped_label(layout, text, icon, context)
        if not operators.osl_problem(context):
            wrapped_label(layout, "A Cycles Rendered view shows the procedural cloud and the proxy "
                          "together: turn the proxy off to judge the render", "INFO", context)


classes = (CLOUDGEN_PT_proxy,)
