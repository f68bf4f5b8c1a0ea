"""N-panel (View3D sidebar, tab "Cloud"): add a cloud, its sliders, the live
preview, the render-settings helper. Every panel starts with status lines:
the native module's import error, and whether the procedural cloud can
render with the scene's settings."""
import bpy

from . import bridge, cloud_object, light_setup, nodes, operators, preview
from .panel import SidebarPanel, wrapped_label

SHAPE_SOURCE = "Shape Source"
SHAPE_SOURCE_ITEMS = (
    ("EXPONENT", "Exponent", "The height profile comes from Shape Exponent"),
    ("CURVE", "Gradient Curve", "The height profile comes from the Shape Gradient curve"),
)


def _shape_socket(obj):
    if not cloud_object.is_cloud(obj):
        return None
    for node in cloud_object.cloud_nodes(obj):
        if node is not None and SHAPE_SOURCE in node.inputs:
            return node.inputs[SHAPE_SOURCE]
    return None


def _get_shape_source(obj):
    sock = _shape_socket(obj)
    return 1 if sock is not None and sock.default_value >= 1 else 0


def _set_shape_source(obj, value):
    sock = _shape_socket(obj)
    if sock is not None:
        sock.default_value = int(value)


def status_lines(context):
    """[(icon, text)] shown at the top of every panel; each one line."""
    lines = []
    if bridge.error():
        lines.append(("ERROR", bridge.error()))
    problem = operators.osl_problem(context)
    if problem:
        lines.append(("INFO", f"No procedural render: {problem} — the cloud needs its baked VDB"))
    return lines


def _draw_status(layout, context):
    for icon, text in status_lines(context):
        wrapped_label(layout, text, icon, context)


def _active_cloud(context):
    obj = context.view_layer.objects.active
    return obj if cloud_object.is_cloud(obj) else None


class CLOUDGEN_PT_main(SidebarPanel, bpy.types.Panel):
    bl_label = "Cloud"
    bl_idname = "CLOUDGEN_PT_main"

    def draw(self, context):
        layout = self.layout
        _draw_status(layout, context)
        row = layout.row(align=True)
        row.prop(context.scene.cloudgen, "cloud_type", text="")
        op = row.operator(operators.CLOUDGEN_OT_add_cloud.bl_idname, text="Add Cloud", icon="ADD")
        op.cloud_type = context.scene.cloudgen.cloud_type
        obj = _active_cloud(context)
        if obj is not None:
            wrapped_label(layout, f"{obj.name}: {obj[cloud_object.TYPE_KEY].replace('_', ' ')}",
                          "OUTLINER_OB_VOLUME", context)
            layout.operator(operators.CLOUDGEN_OT_add_rain.bl_idname)
        layout.operator(operators.CLOUDGEN_OT_render_settings.bl_idname, icon="SCENE")
        light_setup.draw(layout, context)


def _help_button(row, p):
    """A "?" beside a setting: its tooltip is the declared help (the slider's own is Blender's)."""
    op = row.operator(operators.CLOUDGEN_OT_parameter_help.bl_idname, text="", icon="QUESTION", emboss=False)
    op.name = p["name"]


def _draw_sockets(layout, node, params, obj=None):
    for p in params:
        if p["label"] in node.inputs:
            sock = node.inputs[p["label"]]
            if sock.is_linked:
                layout.label(text=f"{p['label']}: linked")
                continue
            if (p["label"] == SHAPE_SOURCE and obj is not None) or p["kind"] == "vector":
                head = layout.row(align=True)
                head.label(text=f"{p['label']}:")
                _help_button(head, p)
                if p["kind"] == "vector":
                    layout.prop(sock, "default_value", text="")
                else:
                    layout.row(align=True).prop(obj, "cloudgen_shape_source", expand=True)
                continue
            row = layout.row(align=True)
            row.prop(sock, "default_value", text=p["label"])
            _help_button(row, p)


class _ParamPanel(SidebarPanel):
    bl_parent_id = "CLOUDGEN_PT_main"
    group = ""

    @classmethod
    def poll(cls, context):
        return _active_cloud(context) is not None and bridge.native() is not None \
            and cloud_object.cloud_material(_active_cloud(context)) is not None

    def params(self):
        return [p for p in bridge.parameters() if p["group"] == self.group and p["kind"] != "curve"
                and p["group"] != "Box"]

    def draw(self, context):
        main, noise = cloud_object.cloud_nodes(_active_cloud(context))
        node = main if nodes.GROUP_OF[self.group] == nodes.MAIN_GROUP else noise
        _draw_sockets(self.layout.column(align=True), node, self.params(), _active_cloud(context))


class CLOUDGEN_PT_cloud_main(_ParamPanel, bpy.types.Panel):
    bl_label = "Cloud Main"
    bl_idname = "CLOUDGEN_PT_cloud_main"
    group = "Cloud Main"

    def draw(self, context):
        _ParamPanel.draw(self, context)
        main, _ = cloud_object.cloud_nodes(_active_cloud(context))
        curve = main.node_tree.nodes.get(nodes.CURVE_NODE)
        if curve is not None:
            self.layout.label(text="Shape Gradient (height profile):")
            self.layout.template_curve_mapping(curve, "mapping")


class CLOUDGEN_PT_cloud_noise(_ParamPanel, bpy.types.Panel):
    bl_label = "Cloud Noise"
    bl_idname = "CLOUDGEN_PT_cloud_noise"
    group = "Cloud Noise"


class CLOUDGEN_PT_animation(_ParamPanel, bpy.types.Panel):
    bl_label = "Animation"
    bl_idname = "CLOUDGEN_PT_animation"
    group = "Animation"

    def draw(self, context):
        _ParamPanel.draw(self, context)
        mat = cloud_object.cloud_material(_active_cloud(context))
        follows = nodes.time_follows_frame(mat)
        op = self.layout.operator(operators.CLOUDGEN_OT_time_from_frame.bl_idname,
                                  text="Time: free" if follows else "Time from Frame",
                                  icon="TIME", depress=follows)
        op.enable = not follows


class CLOUDGEN_PT_preview(SidebarPanel, bpy.types.Panel):
    bl_label = "Preview"
    bl_idname = "CLOUDGEN_PT_preview"
    bl_parent_id = "CLOUDGEN_PT_main"

    @classmethod
    def poll(cls, context):
        return _active_cloud(context) is not None

    def draw(self, context):
        layout = self.layout
        s = context.scene.cloudgen
        row = layout.row(align=True)
        row.prop(s, "preview_axis", expand=True)
        layout.prop(s, "preview_offset", slider=True)
        row = layout.row(align=True)
        row.prop(s, "preview_live", toggle=True)
        row.prop(s, "preview_width")
        row.operator(operators.CLOUDGEN_OT_refresh_preview.bl_idname, text="", icon="FILE_REFRESH")
        if preview.state.error:
            wrapped_label(layout, preview.state.error, "ERROR", context)
        elif preview.icon_id():
            layout.template_icon(icon_value=preview.icon_id(), scale=10.0)


def on_register():
    bpy.types.Object.cloudgen_shape_source = bpy.props.EnumProperty(
        name=SHAPE_SOURCE, items=SHAPE_SOURCE_ITEMS, get=_get_shape_source, set=_set_shape_source,
        description="Where the cloud's height profile comes from (the Shape Source socket of Cloud Main)")


def on_unregister():
    if hasattr(bpy.types.Object, "cloudgen_shape_source"):
        del bpy.types.Object.cloudgen_shape_source


classes = (CLOUDGEN_PT_main, CLOUDGEN_PT_cloud_main, CLOUDGEN_PT_cloud_noise, CLOUDGEN_PT_animation,
           CLOUDGEN_PT_preview)
