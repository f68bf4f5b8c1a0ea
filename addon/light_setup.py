"""Light that makes clouds look like clouds: the "Cloud Sky & Sun" operator (a physical sky,
a matched sun, AgX, exposure, cloud render settings; addon/sky_light.py does the sky), "Meter
Exposure" (a camera's meter: addon/exposure_meter.py), and
the sidebar's check of the settings that make clouds dark in an artist's own scene, each with
its fix. The artist's own lights are never touched unless they press Cloud Sky & Sun."""
import math
import os
import shutil
import tempfile

import bpy
from mathutils import Matrix, Vector

from . import (
    bridge,
    checks,
    cloud_object,
    exposure_meter,
    landscape,
    operators,
    sky_light,
    volume_material,
    volume_object,
)
from .panel import wrapped_label

MIN_BOUNCES = operators.MIN_CLOUD_BOUNCES
# The sidebar's "the sun is hidden" line (sun_hidden): a frame exposed within HIDDEN_HINT_STOPS
# of the Sun lamp's own exposure (sky_light.exposure_for_irradiance) while the clouds take the
# overcast's weight to at least HIDDEN_HINT_WEIGHT (exposure_meter.overcast_weight) renders
# dark. Its share of sunlight is a coarse one (HINT_GRID x HINT_GRID ground points, HINT_STEPS
# per ray: about a sixteenth of Meter Exposure's work), cached until the sun, the camera or a
# cloud changes; Meter Exposure records the exposure it set (METERED_KEY on the scene) and
# the line stays away while the exposure is that one.
HIDDEN_HINT_STOPS = 0.5
HIDDEN_HINT_WEIGHT = 0.5
HINT_GRID, HINT_STEPS = 8, 16
METERED_KEY = "cloudgen_metered_exposure"
_hint_share = {"key": None, "share": 1.0}


def view_azimuth(scene) -> float:
    """Azimuth (degrees, sky_light's convention: 0 = +Y, 90 = +X) the scene camera looks
    along; 0 without a camera."""
    cam = scene.camera
    if cam is None:
        return 0.0
    from mathutils import Vector  # noqa: PLC0415

    v = cam.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0))
    if abs(v.x) < 1e-9 and abs(v.y) < 1e-9:
        return 0.0
    return math.degrees(math.atan2(v.x, v.y))


def dark_settings(scene):
    """[(text, fix)] — settings of this scene that make its clouds render dark or clipped, and
    the fix operator's `what` for each ("" when there is no one-click fix; "METER": Meter
    Exposure is the fix)."""
    if not any(cloud_object.is_cloud(o) for o in scene.objects):
        return []
    found = []
    if scene.render.engine == "CYCLES" and scene.cycles.volume_bounces < MIN_BOUNCES:
        found.append((f"Volume Bounces is {scene.cycles.volume_bounces}: light that scatters more often is "
                      f"lost and thick clouds turn dark grey ({operators.CLOUD_BOUNCES} keeps them white)",
                      "BOUNCES"))
    if scene.render.engine == "CYCLES" and scene.cycles.max_bounces < MIN_BOUNCES:
        found.append((f"Total bounces is {scene.cycles.max_bounces}: it caps Volume Bounces", "BOUNCES"))
    if not found and scene.render.engine == "CYCLES":
        line = _few_bounces(scene.cycles.volume_bounces, scene.cycles.max_bounces)
        if line:
            found.append((line, "BOUNCES"))
    clamp = getattr(scene.cycles, "sample_clamp_indirect", 0.0) if scene.render.engine == "CYCLES" else 0.0
    if 0.0 < clamp * 2.0 ** scene.view_settings.exposure < sky_light.CLAMP_DISPLAY / 2:
        found.append((f"Clamp Indirect {clamp:g} at exposure {scene.view_settings.exposure:.1f} cuts the light "
                      "scattered inside clouds: they render grey", "CLAMP"))
    for _, line in _eevee_outside(scene):
        found.append((line, "EEVEE_RANGE"))
    for _, line in _clipped(scene):
        found.append((line, "CLIP_END"))
    for _, line in _camera_inside(scene):
        found.append((line, "CAMERA_OUT"))
    if scene.view_settings.view_transform == "Standard":
        found.append(("View Transform Standard clips bright clouds to flat white (AgX/Filmic keep the "
                      "highlights)", "VIEW"))
    suns = [o for o in scene.objects if o.type == "LIGHT" and not o.hide_render and o.data.energy > 0]
    world = scene.world
    if not suns and (world is None or not world.use_nodes):
        found.append(("No light and no sky: the clouds are black (Cloud Sky & Sun adds both)", ""))
    hidden = sun_hidden(scene)
    if hidden is not None:
        share, sunny = hidden
        through = "under 1 %" if share < 0.01 else f"about {share:.0%}"
        found.append((f"The clouds hide the sun from the ground around the camera ({through} of its "
                      f"light gets through), and exposure {scene.view_settings.exposure:+.1f} is the sun's "
                      f"({sunny:+.1f}): the frame renders dark. Meter Exposure exposes for the overcast",
                      "METER"))
    return found


def sun_hidden(scene):
    """(share, the sun's exposure) when the scene's clouds hide the Sun lamp from the ground
    around the camera (exposure_meter.overcast_weight(share) >= HIDDEN_HINT_WEIGHT) while the
    frame is exposed for the sun (within HIDDEN_HINT_STOPS of sky_light.exposure_for_irradiance,
    and not what Meter Exposure set); None otherwise, or without a sun, a camera or the core."""
    sun = volume_material.scene_sun(scene)
    if sun is None or sun.data.energy <= 0.0 or scene.camera is None or bridge.native() is None:
        return None
    exposure = scene.view_settings.exposure
    if abs(exposure - float(scene.get(METERED_KEY, math.inf))) < 1e-4:
        return None
    toward, rgb = volume_material.sun_light(sun)
    sunny = sky_light.exposure_for_irradiance(rgb)
    if exposure > sunny + HIDDEN_HINT_STOPS:
        return None
    clouds = rendered_clouds(scene)
    if not clouds:
        return None
    at = scene.camera.matrix_world.translation
    key = (tuple(round(c, 6) for c in toward), tuple(round(c, 6) for c in at), repr(clouds))
    if key != _hint_share["key"]:
        _hint_share.update(key=key, share=_ground_share(clouds, scene, toward, HINT_GRID, HINT_STEPS))
    share = _hint_share["share"]
    if exposure_meter.overcast_weight(share) < HIDDEN_HINT_WEIGHT:
        return None
    return share, sunny


def _few_bounces(volume: int, total: int):
    """The line for a scene whose bounces (Volume Bounces, capped by Total) let a thick cloud
    through with less than nine tenths of its light, with the measured share; None from
    sky_light.LOW_CLOUD_BOUNCES up."""
    n = min(volume, total)
    if n >= sky_light.LOW_CLOUD_BOUNCES:
        return None
    what = f"Volume Bounces is {volume}" if volume <= total else f"Total bounces is {total} (it caps Volume Bounces)"
    share = round(100 * sky_light.cumulus_light_share(n))
    return (f"{what}: a thick cloud keeps only about {share} % of its light (the default cumulus, measured) "
            f"and renders grey; {operators.CLOUD_BOUNCES} keeps it white, for about 3× the time of 32")


def _eevee_outside(scene):
    """[(cloud, line)]: the baked clouds Eevee's Volumetrics Start-End leaves out (wholly or in
    part), with checks.eevee_range's line; a procedural cloud does not render in Eevee at all
    (checks.problems says so)."""
    baked = [o for o in scene.objects
             if cloud_object.is_cloud(o) and o.get(volume_object.SOURCE_KEY, "PROCEDURAL") == "BAKED"
             and checks.renders(o)]
    return [(o, cut[1]) for o, cut in ((o, checks.eevee_range(scene, o)) for o in baked) if cut is not None]


def _rendering_clouds_where(scene, check):
    """[(cloud, line)]: the rendering clouds for which `check(scene, cloud)` has a line."""
    clouds = [o for o in scene.objects if cloud_object.is_cloud(o) and checks.renders(o)]
    return [(o, line) for o, line in ((o, check(scene, o)) for o in clouds) if line is not None]


def _clipped(scene):
    """The rendering clouds the camera's Clip End cuts off (checks.clip_range)."""
    return _rendering_clouds_where(scene, checks.clip_range)


def _camera_inside(scene):
    """The rendering clouds whose box holds the scene camera (checks.camera_inside)."""
    return _rendering_clouds_where(scene, checks.camera_inside)


class CLOUDGEN_OT_fix_dark(bpy.types.Operator):
    """Change the one setting that makes the clouds dark or clipped"""
    bl_idname = "cloudgen.fix_dark"
    bl_label = "Fix"
    bl_options = {"REGISTER", "UNDO"}

    what: bpy.props.EnumProperty(items=(("BOUNCES", "Bounces", "Raise volume and total bounces"),
                                        ("VIEW", "View Transform", "AgX (Filmic before 4.0)"),
                                        ("CLAMP", "Clamp Indirect", "Scale the indirect clamp with the exposure"),
                                        ("EEVEE_RANGE", "Eevee Volumetrics Range",
                                         "Widen Eevee's Volumetrics Start and End to hold every cloud"),
                                        ("CLIP_END", "Camera Clip End",
                                         "Move the camera's Clip End beyond the farthest cloud"),
                                        ("CAMERA_OUT", "Camera Out of the Cloud",
                                         "Move the camera back along its view until the cloud it is "
                                         "inside fits in the frame")))

    def execute(self, context):
        scene = context.scene
        if self.what == "BOUNCES":
            c = scene.cycles
            c.volume_bounces = max(c.volume_bounces, operators.CLOUD_BOUNCES)
            c.max_bounces = max(c.max_bounces, c.volume_bounces)
            self.report({"INFO"}, f"Volume Bounces {c.volume_bounces}, total bounces {c.max_bounces}")
        elif self.what == "CLAMP":
            scene.cycles.sample_clamp_indirect = sky_light.indirect_clamp(scene.view_settings.exposure)
            self.report({"INFO"}, f"Clamp Indirect {scene.cycles.sample_clamp_indirect:.0f}")
        elif self.what == "EEVEE_RANGE":
            start, end = checks.eevee_range_fix(scene, [c for c, _ in _eevee_outside(scene)])
            self.report({"INFO"}, f"Eevee Volumetrics {start:g}–{end:g} m (a longer range spreads Eevee's "
                                  "volume slices further apart: smaller Tile Size if the clouds band)")
        elif self.what == "CLIP_END":
            end = checks.clip_range_fix(scene, [c for c, _ in _clipped(scene)])
            self.report({"INFO"}, f"Camera Clip End {end:g} m")
        elif self.what == "CAMERA_OUT":
            inside = _camera_inside(scene)
            if not inside:
                self.report({"INFO"}, "The camera is inside no cloud")
                return {"CANCELLED"}
            dist = checks.camera_outside_fix(scene, inside[0][0])
            self.report({"INFO"}, f"Camera moved back to {dist:.4g} m from {inside[0][0].name}'s centre, "
                                  f"Clip End {scene.camera.data.clip_end:.4g} m")
        else:
            self.report({"INFO"}, f"View Transform {sky_light.view_transform(scene)}")
        return {"FINISHED"}


class CLOUDGEN_OT_sky_setup(bpy.types.Operator):
    """Daylight for clouds: a physical sky, a sun lamp matched to it, AgX with an exposure for
    the sun's height, and the cloud render settings. Replaces the world; other lights stay"""
    bl_idname = "cloudgen.sky_setup"
    bl_label = "Cloud Sky & Sun"
    bl_options = {"REGISTER", "UNDO"}

    sun_elevation: bpy.props.FloatProperty(
        name="Sun Elevation", default=35.0, min=0.0, max=90.0, subtype="NONE",
        description="Height of the sun above the horizon, degrees (low: warm light, long shadows)")
    sun_azimuth: bpy.props.FloatProperty(
        name="Sun Azimuth", default=150.0, min=-180.0, max=180.0,
        description="Where the sun stands, degrees from the camera's view direction (0: ahead, in "
                    "the picture — backlit clouds with silver linings; 180: behind the camera)")
    landscape: bpy.props.BoolProperty(
        name="Landscape", default=False,
        description="Add rolling ground with fields and woods to the horizon around the camera and the "
                    "haze over it (aerial perspective: far hills, trees and the far part of a layer fade "
                    "into it). Sized for the cloud types' scale, 1 unit = 250 m")
    visibility_km: bpy.props.FloatProperty(
        name="Visibility", default=landscape.VISIBILITY_KM, min=landscape.VISIBILITY_MIN_KM,
        max=landscape.VISIBILITY_MAX_KM, subtype="NONE",
        description="How far one sees through the Landscape's haze, km (Koschmieder: 2 % contrast left "
                    "there). 20-40 a hazy summer day, 80 a clear one, 150-250 the clean air behind a "
                    "cold front. The haze lies between the camera and every cloud: at 80 km it takes a "
                    "third to a half of the shading of a cumulus 15-35 km away")

    @staticmethod
    def _haze_top(scene):
        """The haze's top: landscape's default, or 80 % of the lowest cloud's bottom."""
        bottoms = [min((o.matrix_world @ Vector(c)).z for c in o.bound_box)
                   for o in scene.objects if cloud_object.is_cloud(o)]
        top = landscape.units(landscape.HAZE_TOP_KM)
        low = min(bottoms, default=top / 0.8)
        return min(top, max(0.8 * low, 0.05 * top))

    def execute(self, context):
        scene = context.scene
        context.view_layer.update()  # the camera's matrix_world after edits in this script
        rotation = view_azimuth(scene) + self.sun_azimuth
        try:
            info = sky_light.daylight(scene, self.sun_elevation, rotation)
            if self.landscape:
                at = scene.camera.matrix_world.translation if scene.camera else (0.0, 0.0)
                landscape.landscape(scene, centre=(at[0], at[1]), haze_top=self._haze_top(scene),
                                    visibility_km=self.visibility_km)
        except RuntimeError as exc:
            self.report({"ERROR"}, f"Cloud Sky & Sun: {exc}")
            return {"CANCELLED"}
        volume_material.point_halos(scene)
        for line in operators.apply_render_settings(scene):
            self.report({"INFO"}, line)
        self.report({"INFO"}, f"Sky and sun at {self.sun_elevation:.0f}°: {info['view_transform']}, "
                              f"exposure {info['exposure']:.1f}")
        return {"FINISHED"}


def _elevation(toward) -> float:
    """Degrees above the horizon of the unit direction `toward`."""
    return math.degrees(math.asin(max(min(toward[2], 1.0), -1.0)))


def rendered_clouds(scene):
    """(parameters, world -> model matrix) of each cloud the render shows (its procedural box
    or its baked volume), for exposure_meter.sun_transmittance. A cloud whose parameters or
    box cannot be read is left out."""
    found = []
    for obj in scene.objects:
        if not cloud_object.is_cloud(obj):
            continue
        baked = volume_object.baked_object(obj)
        if obj.hide_render and (baked is None or baked.hide_render):
            continue
        try:  # validated one by one: a cloud the core rejects is left out, the others still count
            values = bridge.resolve_params(cloud_object.params_from_object(obj))
        except (LookupError, ValueError, TypeError):
            continue
        if min(obj.dimensions) <= 0.0:
            continue
        # the unit cube scaled to the box: scaling the inverse back by the box leaves the rotation
        to_model = Matrix.Diagonal((*obj.dimensions, 1.0)) @ obj.matrix_world.inverted_safe()
        found.append((values, [list(row) for row in to_model]))
    return found


def _ground_share(clouds, scene, toward, grid=exposure_meter.SHARE_GRID, steps=exposure_meter.SHARE_STEPS):
    """exposure_meter's share of the sun's direct light (from direction `toward`) through
    `clouds` (rendered_clouds) on a grid x grid disc of exposure_meter.SHARE_RADIUS_KM around the
    scene camera's foot, `steps` per ray."""
    at = scene.camera.matrix_world.translation
    points = exposure_meter.ground_disc((at.x, at.y, at.z), landscape.units(exposure_meter.SHARE_RADIUS_KM), grid)
    return float(exposure_meter.sun_transmittance(clouds, points, toward, bridge.native().density, steps).mean())


def sunlit_share(scene, sun) -> float:
    """The share of the Sun lamp's direct light that reaches the ground within
    exposure_meter.SHARE_RADIUS_KM of the camera through the scene's clouds (1 without clouds
    or the native module)."""
    if scene.camera is None or bridge.native() is None:
        return 1.0
    clouds = rendered_clouds(scene)
    if not clouds:
        return 1.0
    return _ground_share(clouds, scene, volume_material.sun_light(sun)[0])


def metered_exposure(sun, light, share=1.0):
    """(exposure, stops of glare compensation, overcast weight) for a frame whose meter reads
    `light` (scene-linear, exposure_meter.frame_luminance) under the Sun lamp `sun`, where
    `share` of the sun's direct light reaches the ground (sunlit_share): the exposure for the
    lamp's light (sky_light.exposure_for_irradiance), taken down as the gallery takes a frame
    with the sun's glow in it (exposure_meter.glare_compensation), and moved toward the
    overcast's own exposure as the sun is hidden (exposure_meter.blended_exposure). The reading
    is scaled to the sky's own sun at the lamp's height for the glare, as its bound was
    measured under it: an artist's sun twice as strong reads twice the light and gets the same
    compensation."""
    toward, rgb = volume_material.sun_light(sun)
    elevation = max(_elevation(toward), 2.0)
    scale = sky_light.luminance(sky_light.sun_irradiance(elevation)) / max(sky_light.luminance(rgb), 1e-6)
    stops = exposure_meter.glare_compensation(light * scale)
    sunny = sky_light.exposure_for_irradiance(rgb) + stops
    return exposure_meter.blended_exposure(sunny, light, share), stops, exposure_meter.overcast_weight(share)


def overcast_balance(scene, sun, share):
    """Under a deck that hides the sun (exposure_meter.overcast_weight(share) > 0), with the
    scene's white balance on (Blender 4.3+): balance toward the overcast's own light,
    exposure_meter.blended_balance from the sun's (sky_light's, at the lamp's height) and
    return the temperature; otherwise leave the balance as it is and return None."""
    vs = scene.view_settings
    if exposure_meter.overcast_weight(share) <= 0.0 or not getattr(vs, "use_white_balance", False):
        return None
    toward, _ = volume_material.sun_light(sun)
    elevation = _elevation(toward)
    sun_k = max(sky_light.sun_temperature(elevation), sky_light.WHITE_BALANCE_FLOOR_K)
    vs.white_balance_temperature = exposure_meter.blended_balance(sun_k, share)
    return vs.white_balance_temperature


class CLOUDGEN_OT_meter_exposure(bpy.types.Operator):
    """Set the exposure as a camera's meter would, from a small test render (96 x 54): the
    exposure for the sun lamp's light, taken down when the sun's glow fills the frame (a view
    toward the sun through a veil, where the 22° halo would otherwise burn out), and under a
    deck that hides the sun the exposure (and white balance) for the overcast's own light"""
    bl_idname = "cloudgen.meter_exposure"
    bl_label = "Meter Exposure"
    bl_options = {"REGISTER", "UNDO"}

    # From the sidebar (invoke, a window): the meter renders as Blender's render job — progress
    # in the status bar, Esc cancels and leaves the exposure as it was — and the operator waits
    # for it on a timer. From scripts and `blender -b` (execute): rendered there and then.
    # Blender writes a write_still render before it calls render_complete (RE_RenderFrame, 3.4
    # to 5.0): when the handler has run, the EXR is there or the render failed to write it.
    POLL_SECONDS = 0.1

    def _sun(self, scene):
        sun = volume_material.scene_sun(scene)
        if sun is None or sun.data.energy <= 0.0:
            self.report({"ERROR"}, "Meter Exposure needs a Sun lamp that renders (Cloud Sky & Sun adds one)")
            return None
        if scene.camera is None:
            self.report({"ERROR"}, "Meter Exposure needs a scene camera")
            return None
        return sun

    def _apply(self, scene, sun, light, before):
        share = sunlit_share(scene, sun)
        scene.view_settings.exposure, stops, weight = metered_exposure(sun, light, share)
        scene[METERED_KEY] = scene.view_settings.exposure  # the sidebar's sun_hidden line keeps away
        if getattr(getattr(scene, "cycles", None), "sample_clamp_indirect", 0.0) > 0.0:  # kept relative (0: off)
            scene.cycles.sample_clamp_indirect = sky_light.indirect_clamp(scene.view_settings.exposure)
        glare = f", {stops:+.1f} stops for the sun's glare" if stops < 0.0 and weight < 1.0 else ""
        hidden = (f", the sun {1.0 - share:.0%} hidden: exposed {weight:.0%} for the overcast's own light"
                  if weight > 0.0 else "")
        balance = overcast_balance(scene, sun, share)
        if balance is not None:
            hidden += f", white balance {balance:.0f} K"
        self.report({"INFO"}, f"Metered {light:.3g}: exposure {before:+.2f} -> {scene.view_settings.exposure:+.2f}"
                              + glare + hidden)

    def execute(self, context):
        scene = context.scene
        sun = self._sun(scene)
        if sun is None:
            return {"CANCELLED"}
        context.view_layer.update()
        before = scene.view_settings.exposure
        try:
            light = exposure_meter.frame_luminance(scene)
        except RuntimeError as exc:
            self.report({"ERROR"}, f"Meter Exposure: {exc}")
            return {"CANCELLED"}
        self._apply(scene, sun, light, before)
        return {"FINISHED"}

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        scene = context.scene
        if self._sun(scene) is None:
            return {"CANCELLED"}
        context.view_layer.update()
        self._scene_name, self._before = scene.name, scene.view_settings.exposure
        self._tmp = tempfile.mkdtemp(prefix="cloudgen-meter-")
        self._path = os.path.join(self._tmp, "meter.exr")
        self._saved = exposure_meter.meter_settings(scene, self._path)
        self._ended, self._timer = [], None
        self._handlers = ((bpy.app.handlers.render_complete, lambda *_: self._ended.append("complete")),
                          (bpy.app.handlers.render_cancel, lambda *_: self._ended.append("cancel")))
        for handlers, fn in self._handlers:
            handlers.append(fn)
        view = context.preferences.view
        display = view.render_display_type
        view.render_display_type = "NONE"  # no render window for a 96 x 54 test
        try:
            started = bpy.ops.render.render("INVOKE_DEFAULT", write_still=True)
        finally:
            view.render_display_type = display
        if "RUNNING_MODAL" not in started:
            self._end(context)
            self.report({"ERROR"}, "Meter Exposure: the test render did not start (is a render running?)")
            return {"CANCELLED"}
        self._timer = context.window_manager.event_timer_add(self.POLL_SECONDS, window=context.window)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type != "TIMER" or not self._ended:
            return {"PASS_THROUGH"}  # Esc goes to the render job, which cancels itself
        light, error = None, None
        if self._ended[0] == "complete":
            try:
                light = exposure_meter.read_luminance(self._path)
            except RuntimeError as exc:
                error = exc
        scene = self._end(context)
        if error is not None:
            self.report({"ERROR"}, f"Meter Exposure: {error}")
            return {"CANCELLED"}
        if light is None or scene is None:
            self.report({"WARNING"}, "Meter Exposure cancelled: the exposure is as it was")
            return {"CANCELLED"}
        sun = volume_material.scene_sun(scene)
        if sun is None:
            self.report({"ERROR"}, "Meter Exposure: the Sun lamp is gone")
            return {"CANCELLED"}
        self._apply(scene, sun, light, self._before)
        return {"FINISHED"}

    def cancel(self, context):  # the window manager ended the operator (a file loaded, Blender quit)
        self._end(context)

    def _end(self, context):
        """Remove the handlers, the timer and the private folder, put the scene's settings back;
        the scene, or None when it is gone."""
        for handlers, fn in self._handlers:
            if fn in handlers:
                handlers.remove(fn)
        if self._timer is not None:
            context.window_manager.event_timer_remove(self._timer)
            self._timer = None
        shutil.rmtree(self._tmp, ignore_errors=True)
        scene = bpy.data.scenes.get(self._scene_name)
        if scene is not None:
            exposure_meter.restore_settings(scene, self._saved)
        return scene


def draw(layout, context):
    """The sidebar's light section: the operators and what in this scene makes clouds dark."""
    layout.operator(CLOUDGEN_OT_sky_setup.bl_idname, icon="LIGHT_SUN")
    layout.operator(CLOUDGEN_OT_meter_exposure.bl_idname, icon="CAMERA_DATA")
    for text, fix in dark_settings(context.scene):
        # the line across the sidebar's width, its Fix under it (beside it, in a row, the text
        # got half the width and Blender cut its wrapped lines short: "Cumulo…", "End is 1…")
        col = layout.column(align=True)
        wrapped_label(col, text, "ERROR", context)
        if fix == "METER":
            col.operator(CLOUDGEN_OT_meter_exposure.bl_idname, icon="CAMERA_DATA")
        elif fix:
            col.operator(CLOUDGEN_OT_fix_dark.bl_idname, text="Fix").what = fix


classes = (CLOUDGEN_OT_fix_dark, CLOUDGEN_OT_sky_setup, CLOUDGEN_OT_meter_exposure)
