"""Operators: Add Cloud, Add Rain, Refresh Preview, Render Settings, Time from Frame.
All of them work in background mode (no window, area or region needed)."""
import bpy

from . import blender_nodes, bridge, checks, cloud_object, nodes, precipitation, preview, props, volume_material
from .panel import tooltip
from .sky_light import CLOUD_BOUNCES

# Volume bounces for clouds: a thick cloud scatters light many times before it leaves; with
# fewer bounces the lost light makes it grey. CLOUD_BOUNCES comes from sky_light (which says how much).
MIN_CLOUD_BOUNCES = 4  # Add Cloud raises a scene's Volume Bounces below this to CLOUD_BOUNCES


def osl_problem(context):
    """None when the procedural (OSL) cloud can render with the scene's settings,
    else one line saying why not."""
    if not blender_nodes.osl_available():
        return "this Blender build has no Open Shading Language"
    scene = context.scene
    if scene.render.engine != "CYCLES":
        engine = {"BLENDER_EEVEE": "Eevee", "BLENDER_EEVEE_NEXT": "Eevee",
                  "BLENDER_WORKBENCH": "Workbench"}.get(scene.render.engine, scene.render.engine)
        return f"the render engine is {engine}; OSL runs in Cycles only"
    if not scene.cycles.shading_system:
        return "Open Shading Language is off in the render settings"
    if scene.cycles.device == "GPU":
        prefs = context.preferences.addons.get("cycles")
        kind = getattr(prefs.preferences, "compute_device_type", "NONE") if prefs else "NONE"
        if kind != "OPTIX":
            return f"GPU rendering with {kind}: OSL needs the CPU or OptiX"
    return None


class CLOUDGEN_OT_add_cloud(bpy.types.Operator):
    """Add a cloud: a box with the Cloud Main / Cloud Noise volume material"""
    bl_idname = "cloudgen.add_cloud"
    bl_label = "Add Cloud"
    bl_options = {"REGISTER", "UNDO"}

    cloud_type: bpy.props.EnumProperty(name="Cloud Type", items=props.cloud_type_items)

    def execute(self, context):
        if bridge.error():
            self.report({"ERROR"}, f"Add Cloud: {bridge.error()}")
            return {"CANCELLED"}
        try:
            obj = cloud_object.create_cloud(context, self.cloud_type)
        except (RuntimeError, KeyError, ValueError) as exc:
            self.report({"ERROR"}, f"Add Cloud: {exc}")
            return {"CANCELLED"}
        preview.refresh(context, obj)
        volume_material.point_halos(context.scene)  # an ice veil's halo toward the scene's sun
        c = context.scene.cycles
        if context.scene.render.engine == "CYCLES" and c.volume_bounces < MIN_CLOUD_BOUNCES:
            was = c.volume_bounces
            c.volume_bounces = CLOUD_BOUNCES
            c.max_bounces = max(c.max_bounces, CLOUD_BOUNCES)
            self.report({"INFO"}, f"Volume Bounces raised from {was} to {CLOUD_BOUNCES}: with fewer, thick "
                                  "clouds render dark grey (Ctrl+Z to undo)")
        if getattr(c, "use_denoising", False) and not checks.denoiser_available(context.scene):
            c.use_denoising = False  # Debian's 3.4 default scene: on, with no denoiser built in
            self.report({"INFO"}, "Denoise turned off: this Blender has no denoiser for this device and a "
                                  "render with it on fails (Ctrl+Z to undo)")
        inside = checks.camera_inside(context.scene, obj)
        if inside:
            self.report({"WARNING"}, f"{inside} (the sidebar's Cloud tab has a Fix)")
        problem = osl_problem(context)
        if problem:
            self.report({"WARNING"}, f"{obj.name} added; it will not render procedurally: {problem} "
                                     "— render its baked VDB instead")
        return {"FINISHED"}


class CLOUDGEN_OT_add_rain(bpy.types.Operator):
    """Add rain under the active cloud, from its base to the ground (z = 0): a shaft under a
    storm's tower, veils under a layer (docs/lighting.md, Rain)"""
    bl_idname = "cloudgen.add_rain"
    bl_label = "Add Rain"
    bl_options = {"REGISTER", "UNDO"}

    visibility_km: bpy.props.FloatProperty(
        name="Visibility (km)", min=precipitation.VISIBILITY_KM[0], max=precipitation.VISIBILITY_KM[1],
        default=precipitation.DEFAULT_VISIBILITY_KM,
        description="How far one sees through the rain (extinction 3.912 / V): heavy rain 1-2 km, "
                    "moderate about 4; unset: the cloud type's own")
    patchiness: bpy.props.FloatProperty(
        name="Patchiness", min=0.0, max=1.0, default=precipitation.DEFAULT_LOOK["patchiness"],
        description="0: an even veil; 1: curtains with dry air between; unset: the cloud type's own")

    def execute(self, context):
        cloud = context.view_layer.objects.active
        if not cloud_object.is_cloud(cloud):
            self.report({"ERROR"}, "Add Rain: the active object is not a cloud (Add Cloud makes one)")
            return {"CANCELLED"}
        look = dict(precipitation.LOOKS.get(cloud.get(cloud_object.TYPE_KEY, ""), precipitation.DEFAULT_LOOK))
        for key in ("visibility_km", "patchiness"):
            if self.properties.is_property_set(key):
                look[key] = getattr(self, key)
        native = bridge.native()
        if native is None:
            self.report({"ERROR"}, f"Add Rain: {bridge.error()}")
            return {"CANCELLED"}
        centre = tuple(cloud.matrix_world.translation)
        try:
            cx, cy, hx, hy, top = precipitation.rain_box(cloud_object.params_from_object(cloud), centre,
                                                         native.density)
            rain = precipitation.add_rain(context.scene, (cx, cy), hx, hy, top, name=f"{cloud.name} Rain",
                                          rot_z=cloud.matrix_world.to_euler().z, **look)
        except ValueError as exc:
            hint = f". Move {cloud.name} up so that its base is above the ground" if "rain top" in str(exc) else ""
            self.report({"ERROR"}, f"Add Rain: {exc}{hint}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"{rain.name}: {2 * hx:.3g} x {2 * hy:.3g} units, from the ground to "
                              f"{top:.3g}, visibility {look['visibility_km']:g} km")
        return {"FINISHED"}


class CLOUDGEN_OT_refresh_preview(bpy.types.Operator):
    """Recompute the cross-section preview of the active cloud"""
    bl_idname = "cloudgen.refresh_preview"
    bl_label = "Refresh Preview"

    def execute(self, context):
        if not preview.refresh(context):
            self.report({"ERROR"}, preview.state.error)
            return {"CANCELLED"}
        return {"FINISHED"}


class CLOUDGEN_OT_render_settings(bpy.types.Operator):
    """Render settings that suit clouds: Cycles, OSL on the CPU (for the procedural
    cloud), volume step rate and bounces"""
    bl_idname = "cloudgen.render_settings"
    bl_label = "Cloud Render Settings"
    bl_options = {"REGISTER", "UNDO"}

    procedural: bpy.props.BoolProperty(
        name="Procedural (OSL)", default=True,
        description="Render the clouds' OSL shaders (CPU); off for baked VDBs (any device)")
    denoise: bpy.props.BoolProperty(name="Denoise", default=True,
                                    description="Denoise final renders (left off where this "
                                                "Blender has no denoiser)")
    volume_bounces: bpy.props.IntProperty(name="Volume Bounces", default=CLOUD_BOUNCES, min=0, max=1024,
                                          description="Multiple scattering makes clouds bright")
    step_rate: bpy.props.FloatProperty(name="Cloud Step Rate", default=0.0, min=0.0, max=10.0,
                                       description="Volume step rate of the cloud materials (smaller: finer "
                                                   "detail and a more accurate density, slower); 0: each "
                                                   "cloud type's own, from its preset (finer for dense "
                                                   "clouds, coarser for thin ones)")

    def execute(self, context):
        for line in apply_render_settings(context.scene, self.procedural, self.denoise, self.volume_bounces,
                                          self.step_rate):
            self.report({"INFO"}, line)
        problem = osl_problem(context) if self.procedural else None
        if problem:
            self.report({"WARNING"}, f"Procedural clouds will not render: {problem} — use baked VDBs")
        return {"FINISHED"}


def type_step_rate(cloud) -> float:
    """The procedural step rate of the cloud's type (its preset's material; until 2026-11 Render
    Settings set 0.2 on every cloud, overriding every preset's own rate)."""
    look = bridge.presets().get(cloud.get(cloud_object.TYPE_KEY, ""), {}).get("material", {})
    return volume_material.procedural_step_rate(look)


def apply_render_settings(scene, procedural=True, denoise=True, volume_bounces=CLOUD_BOUNCES, step_rate=0.0):
    """Cycles settings that suit clouds (the Cloud Render Settings operator, and Cloud Sky &
    Sun); returns lines worth telling the artist. step_rate 0: each cloud type's own."""
    said = []
    scene.render.engine = "CYCLES"
    c = scene.cycles
    if procedural:
        c.device = "CPU"
        c.shading_system = True
    denoiser = checks.usable_denoiser(scene) if denoise else None
    if denoiser is not None and c.denoiser != denoiser:
        c.denoiser = denoiser
    c.use_denoising = denoiser is not None
    if denoise and denoiser is None:
        said.append("Denoise left off: this Blender has no denoiser for this device "
                    "(built without OpenImageDenoise)")
    c.volume_bounces = volume_bounces
    c.max_bounces = max(c.max_bounces, volume_bounces)
    c.transparent_max_bounces = max(c.transparent_max_bounces, 16)
    for attr, value in (("volume_step_rate", 1.0), ("volume_max_steps", 1024)):
        if hasattr(c, attr):  # Blender 5 renders volumes without ray-marching steps
            setattr(c, attr, value)
    for cloud in (o for o in scene.objects if cloud_object.is_cloud(o)):
        mat = cloud_object.cloud_material(cloud)
        if mat is not None and hasattr(mat.cycles, "volume_step_rate"):
            mat.cycles.volume_step_rate = step_rate if step_rate > 0.0 else type_step_rate(cloud)
    return said


class CLOUDGEN_OT_time_from_frame(bpy.types.Operator):
    """Let the cloud's Time follow the scene frame (frame / fps), or free it again"""
    bl_idname = "cloudgen.time_from_frame"
    bl_label = "Time from Frame"
    bl_options = {"REGISTER", "UNDO"}

    enable: bpy.props.BoolProperty(name="Follow Frame", default=True)

    def execute(self, context):
        mat = cloud_object.cloud_material(context.view_layer.objects.active)
        if mat is None:
            self.report({"ERROR"}, "Time from Frame: the active object is not a cloud")
            return {"CANCELLED"}
        nodes.set_time_from_frame(mat, self.enable)
        return {"FINISHED"}


class CLOUDGEN_OT_parameter_help(bpy.types.Operator):
    """What this setting does"""
    bl_idname = "cloudgen.parameter_help"
    bl_label = "Help"
    bl_options = {"INTERNAL"}

    name: bpy.props.StringProperty(name="Parameter", options={"HIDDEN"})

    @classmethod
    def help_text(cls, name) -> str:
        """The declared help of parameter `name` (no trailing period), "" when unknown."""
        for p in bridge.parameters():
            if p["name"] == name:
                text = tooltip(p["help"])
                return f"{p['label']}: {text}" + (f" ({p['unit']})" if p.get("unit") else "")
        return ""

    @classmethod
    def description(cls, context, properties):
        # Hovering a slider in the sidebar shows Blender's generic socket tooltip
        # (the socket's value property is Blender's own); this button beside it
        # shows the declared help instead.
        return cls.help_text(properties.name) or "No help for this setting"

    def execute(self, context):
        self.report({"INFO"}, self.help_text(self.name) or "No help for this setting")
        return {"FINISHED"}


def menu_add(self, context):
    self.layout.operator_menu_enum(CLOUDGEN_OT_add_cloud.bl_idname, "cloud_type",
                                   text="Cloud", icon="OUTLINER_OB_VOLUME")


MENUS = ("VIEW3D_MT_volume_add", "VIEW3D_MT_mesh_add")

classes = (CLOUDGEN_OT_add_cloud, CLOUDGEN_OT_add_rain, CLOUDGEN_OT_refresh_preview, CLOUDGEN_OT_render_settings,
           CLOUDGEN_OT_time_from_frame, CLOUDGEN_OT_parameter_help)


def on_register():
    for name in MENUS:
        menu = getattr(bpy.types, name, None)
        if menu is not None:
            menu.append(menu_add)


def on_unregister():
    for name in MENUS:
        menu = getattr(bpy.types, name, None)
        if menu is not None:
            menu.remove(menu_add)
