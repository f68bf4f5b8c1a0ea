"""Daylight for clouds: a physical sky, a sun lamp matched to it, a view transform and an
exposure that keep cloud highlights, a white balance for the sun. Used by the add-on's
"Cloud Sky & Sun" operator and by scripts/render_cloud.py (loaded by its path: bpy and
mathutils only, no imports of the add-on's own modules).

The sky is Blender's Nishita sky texture ("Single Scattering" in Blender 5, the same
model) with its sun disc off; the sun is a Sun lamp in the sky's sun direction, 0.545°
wide (the real sun's angular diameter), whose colour and strength are the irradiance of
the sky's own sun disc at that elevation (SUN_IRRADIANCE, measured by
scripts/measure_sky_sun.py: the disc rendered with and without, summed over its solid
angle). A lamp instead of the disc: Cycles samples a lamp directly, while a 0.5° disc in
the world is found only through the background's importance map, which is noisy.
docs/lighting.md has the table, the method and the exposure rule.
"""
import math

import bpy
from mathutils import Vector

SUN_ANGLE_DEG = 0.545
SUN_LAMP = "Cloud Sun"
SKY_WORLD = "Cloud Sky"

# Irradiance (linear Rec.709 RGB, Blender's units) of the Nishita sky's sun disc on a surface
# facing it, by sun elevation in degrees: sun_intensity 1, altitude 0, air/dust/ozone 1.
# Measured with Blender 4.5.15 (scripts/measure_sky_sun.py); below 1° the sun is set.
SUN_IRRADIANCE = (
    (0.0, (0.0, 0.0, 0.0)),
    (1.0, (13.587, 3.626, 0.0)),
    (2.0, (29.820, 10.391, 0.057)),
    (4.0, (59.440, 28.285, 4.257)),
    (6.0, (80.438, 45.156, 12.200)),
    (10.0, (105.346, 69.606, 30.233)),
    (15.0, (121.434, 87.853, 48.753)),
    (20.0, (130.491, 98.917, 62.137)),
    (30.0, (140.145, 111.289, 79.081)),
    (45.0, (146.675, 119.969, 92.243)),
    (60.0, (149.672, 124.032, 98.770)),
    (90.0, (151.490, 126.520, 102.884)),
)
CLAMP_DISPLAY = 10.0  # Cycles' default indirect clamp, meant for exposure 0: kept relative to the display
SKY_SHARE = 0.15  # skylight on a sunlit surface, as a share of the direct sun (exposure rule)
MIDDLE = 3.0      # scene-linear value of a white surface facing the sun after exposure (see exposure_for)
LOOKS = ("AgX - High Contrast", "Filmic - High Contrast", "High Contrast")  # by Blender version
WHITE_BALANCE_FLOOR_K = 4000.0  # a sun lower than this colour temperature is left warm (golden hour)
# Volume bounces for clouds (Add Cloud, Cloud Render Settings, scripts/render_cloud.py): light
# in a thick cloud scatters many times before it leaves, the more so the more forward its phase
# (Mie's g is about 0.85). The default cumulus (optical depth about 90 until 2026-11-29, 225
# since) side-lit in the gallery, in % of its 2,048-bounce radiance, sunlit flank / shaded flank:
# 61 / 43 at 32 bounces, 87 / 78 at 128, 95 / 92 at 256, 99 / 99 at 512 (at 90), for 3.3x the
# time of 32 (docs/render_trade.md). 32 was chosen in 2026-11 for a cumulus a third as dense;
# tests/blender/test_bounces.py holds it. At density 6.0 (2026-11-29) 512 bounces keep 96.4 % of
# its thick body's light (1,024: Cycles' most).
CLOUD_BOUNCES = 512
# The default cumulus's light against volume bounces: the mean of its optically thick body in
# render_cloud.py's sky scene (64x48, 16 spp), as a share of its light at 1,024 bounces
# (measured 2026-11-29 on the cumulus of density 6.0, the test_bounces setup; that test checks
# the 32 and 512 rows again). At density 2.4 (2026-11-28) it was 54.4 % at 32, 87.5 % at 128,
# 99.5 % at 512. The sidebar quotes it for a scene with fewer than LOW_CLOUD_BOUNCES.
CUMULUS_LIGHT_BY_BOUNCES = ((4, 0.118), (8, 0.194), (16, 0.301), (32, 0.479), (64, 0.640), (128, 0.793),
                            (256, 0.903), (512, 0.964), (1024, 1.0))
# below this a thick cloud loses more than a tenth of its light: the first row of the table that keeps
# nine tenths (256 since 2026-11-29; 128 was written here before, when the table said 87.5 % there)
LOW_CLOUD_BOUNCES = min(b for b, share in CUMULUS_LIGHT_BY_BOUNCES if share >= 0.9)


def cumulus_light_share(bounces: int) -> float:
    """The default cumulus's light at `bounces` volume bounces as a share of its converged light:
    CUMULUS_LIGHT_BY_BOUNCES interpolated in log2(bounces), 1 from 1,024. Measured from 4 up
    only (below, the sidebar says "dark grey" and Add Cloud raises it): ValueError there."""
    table = CUMULUS_LIGHT_BY_BOUNCES
    if bounces < table[0][0]:
        raise ValueError(f"bounces {bounces}: the cumulus's light was measured from {table[0][0]} up")
    for (b0, s0), (b1, s1) in zip(table, table[1:]):
        if bounces <= b1:
            t = (math.log2(bounces) - math.log2(b0)) / (math.log2(b1) - math.log2(b0))
            return s0 + t * (s1 - s0)
    return 1.0


def denoiser_built_in() -> bool:
    """This Blender's Cycles has OpenImageDenoise (Debian's 3.4 has not: a render with
    denoising on fails there)."""
    try:
        import _cycles  # noqa: PLC0415 - Cycles' own module says what it was built with
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def sun_irradiance(elevation_deg: float):
    """The sky's sun irradiance (r, g, b) at this elevation (degrees), linearly interpolated."""
    e = min(max(float(elevation_deg), 0.0), 90.0)
    for (e0, c0), (e1, c1) in zip(SUN_IRRADIANCE, SUN_IRRADIANCE[1:]):
        if e <= e1:
            t = (e - e0) / (e1 - e0)
            return tuple(a + (b - a) * t for a, b in zip(c0, c1))
    return SUN_IRRADIANCE[-1][1]


def luminance(rgb) -> float:
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def sun_direction(elevation_deg: float, rotation_deg: float) -> Vector:
    """Unit vector toward the sun of a Nishita sky with these angles (rotation 0: the sun
    lies toward +Y; it turns toward +X as the rotation grows) — checked by rendering the
    disc at the centre of a camera aimed along it (scripts/measure_sky_sun.py)."""
    e, r = math.radians(elevation_deg), math.radians(rotation_deg)
    return Vector((math.cos(e) * math.sin(r), math.cos(e) * math.cos(r), math.sin(e)))


def exposure_for(elevation_deg: float) -> float:
    """Film exposure (stops) that brings a white surface facing the sun to MIDDLE: its
    radiance is about (1 + SKY_SHARE) * E_sun / pi. MIDDLE 3 (not 1): a thick cloud sends
    much of its light out of its other sides (the default cumulus's sunlit side, sun behind
    the camera, measured a third of that surface), and a photographer exposes for the cloud;
    AgX's High Contrast look rolls the rest off. MIDDLE was 5 until 2026-11: the sky came out
    pale and the clouds' sunlit and shaded flanks both sat in AgX's shoulder (two blind
    reviewers: "overexposed", "evenly lit"). The gallery's cumulus side-on, side-lit by a 25°
    sun (display 0-255; sky at the top, horizon, sunlit flank, shaded flank): MIDDLE 5 with
    40 km haze 177/221/225/192; MIDDLE 3 with 80 km haze (landscape.VISIBILITY_KM)
    129/196/203/139 (32 bounces; at 512 and the denser cumulus 109/177/186/169:
    docs/lighting.md). A low sun gets a longer exposure, as a camera would; the floor keeps a
    set sun from blowing up the sky."""
    return exposure_for_irradiance(sun_irradiance(max(elevation_deg, 2.0)))


def exposure_for_irradiance(rgb) -> float:
    """exposure_for's rule for a sun lamp of irradiance `rgb` (its colour times its strength):
    an artist's own sun, brighter or dimmer than the sky's, gets the exposure for its light."""
    lum = max(luminance(rgb), 1e-3)
    return math.log2(MIDDLE * math.pi / ((1.0 + SKY_SHARE) * lum))


def indirect_clamp(exposure: float) -> float:
    """Cycles' indirect clamp for this exposure: its default 10 is in scene-linear units and
    meant for exposure 0; under a physical sky (exposure about -5) it cut multiple scattering
    and darkened the default cumulus's sunlit side by 12 % (display 164 -> 145). Kept at 10
    after exposure, it still stops fireflies."""
    return CLAMP_DISPLAY * 2.0 ** (-exposure)


def sun_temperature(elevation_deg: float) -> float:
    """Correlated colour temperature (K) of the sun lamp at this elevation: its linear
    Rec.709 colour to CIE xy, then McCamy's cubic (good to a few K between 2,800 and
    6,500 K). The Nishita sun measures 3,800 K at 10°, 4,800 K at 30°, 5,200 K at 90°."""
    r, g, b = sun_irradiance(max(elevation_deg, 2.0))
    x_ = 0.4124 * r + 0.3576 * g + 0.1805 * b
    y_ = 0.2126 * r + 0.7152 * g + 0.0722 * b
    z_ = 0.0193 * r + 0.1192 * g + 0.9505 * b
    x, y = x_ / (x_ + y_ + z_), y_ / (x_ + y_ + z_)
    n = (x - 0.3320) / (0.1858 - y)
    return 449.0 * n**3 + 3525.0 * n**2 + 6823.3 * n + 5520.33


def white_balance(scene, elevation_deg: float):
    """White balance for the sun, as a camera set to the light it is in: the sunlit side of a
    cloud comes out white and the sky blue, not cream and grey-blue (a reviewer read the
    unbalanced clouds as beige). A sun cooler than WHITE_BALANCE_FLOOR_K (below about 13°)
    is balanced only to the floor: a low sun stays warm, as a photographer leaves it.
    Blender 4.3+ (earlier versions have no white balance: returns None)."""
    vs = scene.view_settings
    if not hasattr(vs, "use_white_balance"):
        return None
    vs.use_white_balance = True
    vs.white_balance_temperature = max(sun_temperature(elevation_deg), WHITE_BALANCE_FLOOR_K)
    vs.white_balance_tint = 0.0
    return vs.white_balance_temperature


def look(scene) -> str:
    """The view transform's High Contrast look (LOOKS, by Blender version): a photograph's
    contrast; the base look leaves a hazy sky grey. Tried by assignment; returns the look
    now set ("None" where there is none)."""
    for name in LOOKS:
        try:
            scene.view_settings.look = name
            return name
        except TypeError:
            continue
    scene.view_settings.look = "None"
    return "None"


def _sky_type(node) -> str:
    items = {i.identifier for i in node.bl_rna.properties["sky_type"].enum_items}
    for name in ("NISHITA", "SINGLE_SCATTERING"):  # Blender 5 renamed Nishita
        if name in items:
            return name
    raise RuntimeError("this Blender's Sky Texture has no Nishita (single scattering) model")


def view_transform(scene) -> str:
    """AgX where the Blender has it (4.0+), else Filmic; both roll highlights off instead of
    clipping them in one channel (Standard turns a bright cloud cyan or flat white). Tried by
    assignment: the bpy wheel lists no view transforms in the enum's RNA (it reads 'NONE')
    although the assignment works. Returns the transform now set."""
    for name in ("AgX", "Filmic"):
        try:
            scene.view_settings.view_transform = name
            return name
        except TypeError:
            continue
    return scene.view_settings.view_transform


def make_sky(scene, elevation_deg: float, rotation_deg: float):
    """A world named SKY_WORLD with the Nishita sky (sun disc off: the lamp is the sun)."""
    world = bpy.data.worlds.get(SKY_WORLD) or bpy.data.worlds.new(SKY_WORLD)
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    sky = nt.nodes.new("ShaderNodeTexSky")
    sky.sky_type = _sky_type(sky)
    sky.sun_disc = False
    sky.sun_elevation = math.radians(elevation_deg)
    sky.sun_rotation = math.radians(rotation_deg)
    sky.sun_size = math.radians(SUN_ANGLE_DEG)
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    sky.location, bg.location, out.location = (-300, 0), (0, 0), (200, 0)
    nt.links.new(sky.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    scene.world = world
    return world


def make_sun(scene, elevation_deg: float, rotation_deg: float):
    """The Sun lamp SUN_LAMP, made or updated: the sky's sun direction, colour and strength."""
    obj = bpy.data.objects.get(SUN_LAMP)
    if obj is None or obj.type != "LIGHT" or obj.data.type != "SUN":
        obj = bpy.data.objects.new(SUN_LAMP, bpy.data.lights.new(SUN_LAMP, "SUN"))
    if scene.collection.objects.get(obj.name) is None and obj.name not in scene.objects:
        scene.collection.objects.link(obj)
    rgb = sun_irradiance(elevation_deg)
    peak = max(rgb)
    obj.data.color = tuple(c / peak for c in rgb) if peak > 0 else (1.0, 1.0, 1.0)
    obj.data.energy = peak
    obj.data.angle = math.radians(SUN_ANGLE_DEG)
    obj.rotation_euler = sun_direction(elevation_deg, rotation_deg).to_track_quat("Z", "Y").to_euler()
    if hasattr(obj, "visible_camera"):  # the disc itself in shot (Blender leaves a new sun lamp unseen)
        obj.visible_camera = True
    return obj


def daylight(scene, elevation_deg=35.0, rotation_deg=0.0):
    """Sky, sun, view transform, look, white balance and exposure for clouds (the ground and
    the haze: addon/landscape.py). Returns a dict of what it set (for reports and tests)."""
    if not (-90.0 <= elevation_deg <= 90.0):
        raise ValueError(f"sun elevation must be in [-90, 90] degrees, not {elevation_deg}")
    make_sky(scene, elevation_deg, rotation_deg)
    sun = make_sun(scene, elevation_deg, rotation_deg)
    view = view_transform(scene)
    looked = look(scene)
    balance = white_balance(scene, elevation_deg)
    scene.view_settings.exposure = exposure_for(elevation_deg)
    scene.view_settings.gamma = 1.0
    if hasattr(scene, "cycles"):
        scene.cycles.sample_clamp_indirect = indirect_clamp(scene.view_settings.exposure)
    return {"view_transform": view, "look": looked, "white_balance": balance, "exposure": scene.view_settings.exposure,
            "clamp_indirect": getattr(getattr(scene, "cycles", None), "sample_clamp_indirect", None),
            "sun_strength": sun.data.energy, "sun_color": tuple(sun.data.color)}
