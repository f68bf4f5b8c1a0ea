"""The gallery's scenes (scripts/gallery.py): where the clouds stand, where the camera looks
from, what else is in shot. Pure geometry and bakes here; Blender objects in add_* (bpy).

Scale: 1 scene unit = addon/landscape.py's METRES_PER_UNIT (250 m), the presets' scale.

- Compact types (cumulus, congestus, cumulonimbus) stand at their WMO base height with
  companions: a field of smaller cumulus of other seeds, every base at the one condensation
  level (COMPANIONS). A lone cloud over an empty plain reads as a toy; a field, shrinking in
  perspective toward the horizon, reads as weather.
- Layers are baked as nested_levels(name) nested boxes around the camera, each twice as wide as
  the next and with its own voxel size (a pixel's footprint where it is used): the outermost runs
  until its far edge is far_edge_deg(name) above the horizon, where the haze takes it. A layer's
  field inside the inner half of any box wider than it equals the widest box's field (the
  Sheet fade acts only on the outer half; the noise is in scene units), so each level
  renders only its ring (a mask in its material) and the rings join without a seam in the
  field, only in the voxel size. Each level is baked as a full square out to its ring's outer
  edge (a hole in a VDB made Cycles lose density in a wedge behind it: scripts/gallery.py).
"""
import math

from render_cloud import is_layer  # the one layer rule (gallery.py reads it from here)

EYE = 0.017  # eye height, scene units (1.7 m)
# cloud base above the ground, km: typical WMO heights
BASE_KM = {"cumulus": 1.2, "cumulus_congestus": 1.2, "cumulonimbus": 1.0, "stratocumulus": 1.0,
           "stratus": 0.35, "nimbostratus": 0.7, "altocumulus": 3.0, "altostratus": 3.5,
           "cirrocumulus": 6.5, "cirrus": 7.5, "cirrostratus": 8.0}
# (companion preset, how many side-on and from below, scale range) beside a compact type's main
# cloud; side-on the field runs out to COMPANION_FAR, from below the 24 mm frame holds fewer
COMPANIONS = {"cumulus": ("cumulus", (100, 24), (0.3, 1.1)),
              "cumulus_congestus": ("cumulus", (60, 20), (0.35, 1.1)),
              "cumulonimbus": ("cumulus", (40, 16), (0.5, 1.4))}


def _curve(fn):
    """A 17-sample height curve (Shape Curve: the squared radius at heights 0..1) from fn(h)."""
    return [round(max(0.0, fn(i / 16.0)), 3) for i in range(17)]


def _capped(r2, flat, power=2.0):
    """Squared radius r2 up to height `flat`, then a top rounded as 1 - t^power."""
    return _curve(lambda h: r2 if h < flat else r2 * (1.0 - ((h - flat) / (1.0 - flat)) ** power))


def _turret_on_body(h):
    """A body of squared radius 0.45 up to 35 % of the height, narrowing steeply into a turret of
    0.18 that rounds off at the top."""
    if h < 0.35:
        return 0.45
    return max(0.45 - 2.7 * (h - 0.35), 0.18 * (1.0 - ((h - 0.45) / 0.55) ** 2))


# each companion bake: a seed, a body of its own (Shape Curve) and what else it changes of the
# preset, so that the field is not one template. Until round 24 the variants changed only the
# noise and all six kept the preset's dome: their silhouettes (a projection through the box) were
# one shape, and every blind round named them "cloned cotton-balls", "pills", "stickers". Now:
# the preset, a flat humilis cap, a narrow ragged one, a small tower, one leaning in the wind
# shear, and a body with one turret on it (distortion lowered where it would fill the body out
# to the preset's dome again). No body is widest at its base: a cap widest there, or a broad
# base under a turret, came out side-on as a hat with a brim (round 25 trial)
COMPANION_VARIANTS = (
    {},
    {"shape_curve": _capped(0.75, 0.1), "turret_influence": 0.15, "distortion": 0.7},
    {"shape_curve": _capped(0.3, 0.2), "edge_sharpness": 0.55, "noise_influence": 0.55, "density_scale": 2 / 3,
     "distortion": 0.9},
    {"shape_curve": _capped(0.2, 0.7), "turret_influence": 0.65, "distortion": 0.9},
    {"shape_curve": _capped(0.35, 0.3, 1.5), "lean": 0.5, "worley_clump": 0.9, "turret_scale": 3.5,
     "distortion": 0.9},
    {"shape_curve": _curve(_turret_on_body),
     "turret_influence": 0.3, "noise_influence": 0.45, "edge_sharpness": 0.75, "distortion": 0.8},
)
# side views: companions out to this many times the main cloud's distance; with 14 out to 8 times
# the sky under the main cloud was empty down to the horizon, where a real field closes up
COMPANION_FAR = 20.0
# the companions stand in clusters: CLUSTER_MEMBERS (fewest, most) around each centre, offset by a
# Gaussian of CLUSTER_SPREAD_KM on the ground; a member that fits nowhere in more than CLUSTER_TRIES
# draws ends its cluster
CLUSTER_MEMBERS = (2, 6)
CLUSTER_SPREAD_KM = 0.8
CLUSTER_TRIES = 40
# from below, a cluster's centre stands BELOW_NEAR to BELOW_FAR times the main cloud's distance
# away (log-uniform), across the frame's width at that distance, and only companions that reach
# into the picture count (none nearer than the main cloud in front of it). Until round 27 the
# centres were drawn on the ground around the main cloud (2.5 times its distance either side,
# -0.5 to 4 times ahead of it): the 24 mm frame held 7 of the cumulus's 24 companions and none of
# the congestus's 20
BELOW_NEAR, BELOW_FAR = 0.3, 4.0
# the main cloud's bake resolution as a multiple of --resolution: the cumulonimbus's box is 45 km
# wide for its anvil, its tower a sixth of that (at 256 voxels a voxel would be 176 m)
MAIN_RESOLUTION_SCALE = {"cumulonimbus": 2}
# side views: the camera at least this many box widths from the main cloud (the cumulonimbus's
# anvil reaches only the middle of its wide box; at 1.2 the storm filled half the frame's width)
SIDE_DISTANCE = {"cumulonimbus": 0.8}
# below views: aim at this fraction of the cloud's height, at this elevation (degrees), from at
# least this many box widths; default (0.3, 55, 0.6). The congestus is taller than wide: from
# under it (round 6) its base filled the frame and it read as a cumulus; from 4 km at 30 degrees
# its base sits low in the frame and its towers rise to the top edge. The cumulonimbus's box is
# 45 km wide for its anvil: 0.6 of it put the camera 27 km away, looking 10 degrees up; from
# 16 km at 25 degrees its tower fills the frame and the anvil overhangs the top. The cumulus
# looked at 55 degrees up showed its flat base as a round dark disc with a beaded rim ("a round
# disc with a dark grey, blurred centre", round 14: realism 1); at 35 degrees its base is a
# foreshortened band under a sunlit dome, other cumulus below it toward the horizon.
BELOW_AIM = {"cumulus": (0.45, 35.0, 0.6), "cumulus_congestus": (0.45, 30.0, 0.6),
             "cumulonimbus": (0.5, 25.0, 0.35)}
# below views of low grey layers: pitched this much (degrees; default 50) so that the ground shows:
# the far hill tops vanish into a stratus's base, the rain under a nimbostratus hides the
# distance. Looking 50 degrees up, both were a plain grey field and were named as one another
# (round 8: stratus as altostratus, nimbostratus as stratus).
LAYER_BELOW_PITCH = {"stratus": 20.0, "nimbostratus": 20.0}
FAR_EDGE_DEG = 1.0
NESTED_LEVELS = 4
# overcast decks reach closer to the horizon, with two more levels (each twice as wide): with
# their far edge 1 degree up, the clear sky beyond it showed side-on as a bright strip along the
# horizon (altostratus, rounds 10-12: "a bright, hard-edged strip runs the full width at the
# horizon"); at 0.3 degrees the deck runs into the hills and the haze (altostratus side-on,
# 320x180, 8 spp: the strip's peak 77 over a deck of 55 became a smooth fall 59 -> 53 -> 47).
# Raising the haze to 80 % of the deck's base instead left the strip (peak 74).
# the overcast decks (one list: gallery.py balances and meters these too)
OVERCAST = ("stratus", "nimbostratus", "altostratus")
OVERCAST_FAR_EDGE_DEG = 0.3
OVERCAST_EXTRA_LEVELS = 2


def companion_count(name, view) -> int:
    """How many companions stand beside a compact type's main cloud in this view."""
    side, below = COMPANIONS[name][1]
    return side if view == "side" else below


def companion_values(name, i):
    """The parameters of a compact type's companion bake i (of len(COMPANION_VARIANTS)): the
    companion preset over the defaults, variant i over that, seed 101 + i."""
    import cloudgen_native as cn

    comp = COMPANIONS[name][0]
    variant = dict(COMPANION_VARIANTS[i])
    values = dict(cn.defaults(), **cn.presets()[comp]["params"])
    if "density_scale" in variant:  # a fraction of the preset's density, which is declared once
        values["density"] *= variant.pop("density_scale")
    return dict(values, **variant, seed=101 + i)


def far_edge_deg(name) -> float:
    return OVERCAST_FAR_EDGE_DEG if name in OVERCAST else FAR_EDGE_DEG


def nested_levels(name) -> int:
    return NESTED_LEVELS + (OVERCAST_EXTRA_LEVELS if name in OVERCAST else 0)


THICKNESS_VOXELS = 32  # a layer's voxel is at most its thickness / this (smooth decks need no finer)
PIXELS_PER_VOXEL = 1.5
MAX_LEVEL_VOXELS = 2.5e8  # evaluated voxels per level bake (memory and time)
HORIZON_FROM_BOTTOM = 0.12  # side views: the horizon this far up the frame
SIDE_LENS, BELOW_LENS = 35.0, 24.0
MAIN_TOP_FROM_BOTTOM = 0.86  # side views: the main compact cloud's top this far up


def km(v: float) -> float:
    return v * 4.0  # 250 m per unit (addon/landscape.py METRES_PER_UNIT)


def tans(lens: float, width: int, height: int):
    """tan of half the horizontal and vertical field of view (36 mm sensor, horizontal fit)."""
    tx = 18.0 / lens
    return tx, tx * height / width


def pitch_for_horizon(tan_y: float, from_bottom: float = HORIZON_FROM_BOTTOM) -> float:
    """Camera pitch (degrees up) that puts the horizon `from_bottom` of the frame's height
    above its bottom edge."""
    return math.degrees(math.atan((1 - 2 * from_bottom) * tan_y))


def vertical_extent(values) -> tuple:
    """(bottom, top) of the cloud as fractions of the box height, from a cross-section
    through the box's centre (the shape decides; the noise may not reach the box)."""
    import cloudgen_native as cn
    import numpy as np

    rows = np.flatnonzero(cn.slice(values, "y", 0.5, 96, 192).max(axis=1) > 0)
    if rows.size == 0:
        return 0.0, 1.0
    return 1.0 - (rows[-1] + 1) / 192.0, 1.0 - rows[0] / 192.0  # row 0 is the top


def horizontal_middle(values) -> float:
    """The middle of the cloud's x extent as a fraction of the box width, from the same
    cross-section (0.5 for a cloud centred in its box; a leaning anvil moves it downwind)."""
    import cloudgen_native as cn
    import numpy as np

    cols = np.flatnonzero(cn.slice(values, "y", 0.5, 192, 96).max(axis=0) > 0)
    if cols.size == 0:
        return 0.5
    return (cols[0] + cols[-1] + 1) / 2 / 192.0


def compact_view(name, values, view, width, height):
    """For a compact type: (main cloud centre, camera location, pitch degrees, lens)."""
    bx, by, bz = values["box_size"]
    z0, z1 = vertical_extent(values)
    base = km(BASE_KM.get(name, 1.2))
    centre_z = base + (0.5 - z0) * bz  # the cloud's lowest point at the base height
    top = base + (z1 - z0) * bz
    if view == "below":
        tx, ty = tans(BELOW_LENS, width, height)
        aim_at, elevation, widths = BELOW_AIM.get(name, (0.3, 55.0, 0.6))
        aim = base + aim_at * (z1 - z0) * bz
        d = max(aim / math.tan(math.radians(elevation)), widths * max(bx, by))
        return (0.0, d, centre_z), (0.0, 0.0, EYE), math.degrees(math.atan2(aim - EYE, d)), BELOW_LENS
    tx, ty = tans(SIDE_LENS, width, height)
    pitch = pitch_for_horizon(ty)
    top_elevation = math.radians(pitch) + math.atan((2 * MAIN_TOP_FROM_BOTTOM - 1) * ty)
    # the near side of the box (half its depth nearer than the centre) is what reaches highest
    d = max(top / math.tan(top_elevation) + by / 2, SIDE_DISTANCE.get(name, 1.2) * max(bx, by))
    # the cloud's own middle (not its box's) in the middle of the frame, where it is off by more
    # than 5 % of the box (the cumulonimbus's anvil; the others stay where round 6 had them)
    off = horizontal_middle(values) - 0.5
    centre_x = -off * bx if abs(off) > 0.05 else 0.0
    return (centre_x, d, centre_z), (0.0, 0.0, EYE), pitch, SIDE_LENS


def companions(name, main_values, main_centre, view, width, height, rng):
    """[(x, y, z, (sx, sy, sz), rot_z)] of the companion clouds, companion i baked from
    companion_values(name, i % len(COMPANION_VARIANTS)): in the camera's view wedge
    (side) or reaching into the picture (below), not overlapping each other or the main cloud,
    their lowest points at the main cloud's base height. Each is one of a few seeds, so each
    gets its own proportions too (x and y 0.75-1.5 of its scale, height 0.45-1.1): four
    seeds at one aspect read as clones ("bread loaves", blind review round 5).

    They stand in clusters (CLUSTER_MEMBERS around a centre, offsets a Gaussian of
    CLUSTER_SPREAD_KM), as thermals group over warm ground, and they may overlap in the
    picture where they stand at about one distance (side by side, one bank) but never one on
    top of another (_rects_stack; side-on since round 5, from below since round 25). Until
    round 22 every centre was drawn on its own and no
    two of similar picture size might touch: an evenly spaced field, "near-identical puffs on
    a regular grid", "cloned stamps in regular rows" (rounds 21-22, both reviewers)."""
    if name not in COMPANIONS:
        return []
    _, _, (s_lo, s_hi) = COMPANIONS[name]
    count = companion_count(name, view)
    mx, my, _ = main_values["box_size"]
    variants = [companion_values(name, i) for i in range(len(COMPANION_VARIANTS))]
    extents = [vertical_extent(v) for v in variants]
    base = km(BASE_KM.get(name, 1.2))
    tx, ty = tans(SIDE_LENS if view == "side" else BELOW_LENS, width, height)
    main_r = 0.5 * math.hypot(mx, my)
    d = main_centre[1]
    pitch = compact_view(name, main_values, view, width, height)[2]
    mz0, mz1 = vertical_extent(main_values)
    main_rect = _screen_rect(main_centre[0], d, main_r, base, (mz1 - mz0) * main_values["box_size"][2], pitch)
    rects = [] if main_rect is None else [main_rect]
    placed = []
    tries = 0
    members_left = cluster_draws = 0
    while len(placed) < count and tries < 8000:
        tries += 1
        if members_left <= 0 or cluster_draws > CLUSTER_TRIES:  # a new cluster's centre
            if view == "side":
                centre_y = d * math.exp(rng.uniform(math.log(0.5), math.log(COMPANION_FAR)))
                centre_x = rng.uniform(-1.2, 1.2) * centre_y * tx
            else:
                centre_y = d * math.exp(rng.uniform(math.log(BELOW_NEAR), math.log(BELOW_FAR)))
                p = math.radians(pitch)
                depth = centre_y * math.cos(p) + (base - EYE) * math.sin(p)
                centre_x = rng.uniform(-1.1, 1.1) * tx * depth  # across the frame's width at that depth
            members_left, cluster_draws = rng.randint(*CLUSTER_MEMBERS), 0
        cluster_draws += 1
        cx, cy, cz = variants[len(placed) % len(variants)]["box_size"]
        z0, z1 = extents[len(placed) % len(variants)]
        s = s_lo * (s_hi / s_lo) ** rng.random()  # log-uniform: more small ones than big ones
        sx, sy, sz = (s * rng.uniform(0.75, 1.5), s * rng.uniform(0.75, 1.5), s * rng.uniform(0.45, 1.1))
        r = 0.5 * math.hypot(cx * sx, cy * sy)
        x = centre_x + rng.gauss(0.0, km(CLUSTER_SPREAD_KM))
        y = centre_y + rng.gauss(0.0, km(CLUSTER_SPREAD_KM))
        if view == "side" and not (0.5 * d < y and abs(x) < 1.3 * y * tx):  # in the view wedge
            continue
        if math.hypot(x - main_centre[0], y - main_centre[1]) < main_r + r:
            continue
        if view == "side" and y < d and abs(x) < main_r + r:  # in front of the main cloud
            continue
        if any(math.hypot(x - px, y - py) < 0.8 * (r + pr) for px, py, _, _, pr in placed):
            continue
        # a far body's top under a near one's base reads as one stacked cloud: side-on a
        # "snowman", from below a "mushroom" (round 25, both reviewers)
        rect = _screen_rect(x, y, r, base, cz * sz * (z1 - z0), pitch)
        if rect is not None and any(_rects_stack(rect, q) for q in rects):
            continue
        if view == "below" and (rect is None or not rects_overlap(rect, (-tx, tx, -ty, ty))
                                or (y < d and main_rect is not None and rects_overlap(rect, main_rect))):
            continue  # from below: only what the picture holds, nothing in front of the main cloud
        if math.hypot(x, y) < r + km(0.3):  # not over the camera
            continue
        z = base + (0.5 - z0) * cz * sz
        placed.append((x, y, z, (sx, sy, sz), r))
        members_left -= 1
        if rect is not None:
            rects.append(rect)
    return [(x, y, z, sc, rng.uniform(0.0, 2 * math.pi)) for x, y, z, sc, _ in placed]


def _screen_rect(x, y, r, base, height, pitch):
    """The picture-plane rectangle (tan units: left, right, bottom, top) of a cloud standing
    on `base` with horizontal radius r and the given height, seen by the gallery's camera (at
    eye height on the origin, looking along +y, pitched up `pitch` degrees); None when a corner
    of its box is not in front of the camera (depth under 1e-3 units)."""
    p = math.radians(pitch)
    us, vs = [], []
    for cx in (x - r, x + r):
        for cy in (y - r, y + r):
            for cz in (base - EYE, base + height - EYE):
                depth = cy * math.cos(p) + cz * math.sin(p)
                if depth < 1e-3:
                    return None
                us.append(cx / depth)
                vs.append((cz * math.cos(p) - cy * math.sin(p)) / depth)
    return min(us), max(us), min(vs), max(vs)


def _rects_stack(a, b, margin=0.15, ratio=2.5, same_base=0.25) -> bool:
    """Whether two picture rectangles of similar width (within `ratio`) overlap once each is
    shrunk by `margin` of its size (the rounded clouds fill their boxes' corners only partly)
    and one stands on the other: their bottoms (the one base height at two distances) differ
    by more than `same_base` of the lower one's height. Side by side at about one distance
    they are one bank of cloud, as in a real field; a far cloud much smaller than a near one
    may pass behind it."""
    wa, wb = a[1] - a[0], b[1] - b[0]
    if max(wa, wb) > ratio * min(wa, wb):
        return False
    def shrunk(q):
        dx, dy = margin * (q[1] - q[0]) / 2, margin * (q[3] - q[2]) / 2
        return q[0] + dx, q[1] - dx, q[2] + dy, q[3] - dy
    if not rects_overlap(shrunk(a), shrunk(b)):
        return False
    lower = a if a[2] < b[2] else b
    return abs(a[2] - b[2]) > same_base * (lower[3] - lower[2])


def rects_overlap(a, b) -> bool:
    """Whether two picture rectangles (left, right, bottom, top) overlap."""
    return a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]


def widened(name, values):
    """A layer's parameters with its box widened (never narrowed) so that, seen from its
    centre, its far edge lies far_edge_deg(name) above the horizon."""
    box = list(values["box_size"])
    if not is_layer(values):
        return values
    need = 2 * km(BASE_KM.get(name, 2.5)) / math.tan(math.radians(far_edge_deg(name)))
    if max(box[0], box[1]) >= need:
        return values
    return dict(values, box_size=[max(box[0], need), max(box[1], need), box[2]])


def layer_levels(name, values, width):
    """The nested bakes of a (widened) layer: [(values, resolution, inner, outer)] from the
    widest box in; level k renders where inner <= max(|x|, |y|) < outer (scene units from
    the centre; outer None: to the edge). Voxel: PIXELS_PER_VOXEL footprints of a 24 mm
    lens's pixel at the nearest distance the level is seen from, capped by MAX_LEVEL_VOXELS."""
    box = values["box_size"]
    wide = max(box[0], box[1])
    base = km(BASE_KM.get(name, 2.5))
    tan_x = 18.0 / BELOW_LENS
    levels = []
    levels_count = nested_levels(name)
    for k in range(levels_count):
        size = wide / 2 ** k
        inner = wide / 2 ** (k + 3) if k < levels_count - 1 else 0.0
        outer = None if k == 0 else wide / 2 ** (k + 2)
        nearest = math.hypot(base, inner)
        voxel = PIXELS_PER_VOXEL * nearest * 2 * tan_x / width
        # The thickness relaxation leaves a low textured deck coarse overhead (stratocumulus: 6
        # pixels a voxel straight up, "out of focus"). Without it and with 6 rings the voxels were
        # 1.5 pixels, but Cycles steps by the voxel: the first of 16 samples took 12 min where the
        # whole image had taken 9. Needs the material's step rate raised with the finer voxel.
        voxel = max(voxel, min(box[2] / THICKNESS_VOXELS, 4 * voxel))
        voxel = max(voxel, (size * size * box[2] / MAX_LEVEL_VOXELS) ** (1 / 3))
        res = int(math.ceil(size / voxel))
        lv = dict(values, box_size=[box[0] / 2 ** k, box[1] / 2 ** k, box[2]])
        levels.append((lv, res, inner, outer))
    return levels


# Box-filtered level bakes (`cloudgen bake --supersample 2`, docs/camera.md) where a layer is
# thin in voxels: through fewer than THIN_LAYER_VOXELS voxels the noise's edges are sharper than
# a voxel in z and a point sample aliases them (the cirrocumulus's innermost level: RMS error
# against the cells' means 0.26 point-sampled, 0.07 box-filtered, tests/native/test_supersample.cpp).
# Thinner than a voxel (the veils' outer levels), a point sample made the layer a whole voxel thick:
# the cirrostratus's outer rings came out 1.9x and 7.6x too dense at 0.8 and 3.2-unit voxels, and
# side-on the veil brightened in steps at the rings' seams. The box filter samples only the cell's
# part inside the box (src/grid.cpp), 3 per axis there: +9 % in the column (2: +16 %).
THIN_LAYER_VOXELS = 8
LEVEL_SUPERSAMPLE = 2
SUB_VOXEL_SUPERSAMPLE = 3


def level_supersample(level_values, resolution) -> int:
    """Samples per voxel axis for one level bake of a layer (1 = the voxel's centre)."""
    b = level_values["box_size"]
    z_voxels = b[2] * resolution / max(b)
    if z_voxels < 1.0:
        return SUB_VOXEL_SUPERSAMPLE
    return LEVEL_SUPERSAMPLE if z_voxels < THIN_LAYER_VOXELS else 1


def layer_view(name, values, view, width, height):
    """For a layer: (centre, camera, pitch, lens) — the camera under the middle of the
    nested levels."""
    bz = values["box_size"][2]
    base = km(BASE_KM.get(name, 2.5))
    centre = (0.0, 0.0, base + bz / 2)
    if view == "below":
        return centre, (0.0, 0.0, EYE), LAYER_BELOW_PITCH.get(name, 50.0), BELOW_LENS
    _, ty = tans(SIDE_LENS, width, height)
    return centre, (0.0, 0.0, EYE), pitch_for_horizon(ty), SIDE_LENS


def haze_top(name) -> float:
    """The haze's top, scene units: the Landscape option's rule (addon/light_setup.py) — its
    default height, or 80 % of a lower cloud base."""
    return min(km(0.8), 0.8 * km(BASE_KM.get(name, 1.2)))


# ------------------------------------------------------------------ Blender objects ---


def _volume_material():
    """addon/volume_material.py (bpy), whose node names the masks use."""
    import render_cloud

    return render_cloud._addon_file("volume_material")


def ring_mask(mat, inner: float, outer):
    """Multiply the density of mat's cloud volume by 1 where inner <= max(|x|, |y|) < outer
    in object coordinates, 0 elsewhere (outer None: no outer limit); its halo's density too
    (addon/volume_material.py's HALO_DENSITY: the mask goes into its second factor)."""
    nt = mat.node_tree
    coords = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(coords.outputs["Object"], sep.inputs[0])
    ax = nt.nodes.new("ShaderNodeMath")
    ax.operation = "ABSOLUTE"
    ay = nt.nodes.new("ShaderNodeMath")
    ay.operation = "ABSOLUTE"
    nt.links.new(sep.outputs["X"], ax.inputs[0])
    nt.links.new(sep.outputs["Y"], ay.inputs[0])
    m = nt.nodes.new("ShaderNodeMath")
    m.operation = "MAXIMUM"
    nt.links.new(ax.outputs[0], m.inputs[0])
    nt.links.new(ay.outputs[0], m.inputs[1])
    keep = nt.nodes.new("ShaderNodeMath")
    keep.operation = "GREATER_THAN"  # 1 where m > inner - tiny
    nt.links.new(m.outputs[0], keep.inputs[0])
    keep.inputs[1].default_value = inner - 1e-6
    if outer is not None:
        below = nt.nodes.new("ShaderNodeMath")
        below.operation = "LESS_THAN"
        nt.links.new(m.outputs[0], below.inputs[0])
        below.inputs[1].default_value = outer
        both = nt.nodes.new("ShaderNodeMath")
        both.operation = "MULTIPLY"
        nt.links.new(keep.outputs[0], both.inputs[0])
        nt.links.new(below.outputs[0], both.inputs[1])
        keep = both
    density = _volume_material().density_input(nt)
    if density.is_linked:  # Volume Scatter: grid attribute -> Density; multiply it in
        src = density.links[0].from_socket
        mul = nt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        nt.links.new(src, mul.inputs[0])
        nt.links.new(keep.outputs[0], mul.inputs[1])
        nt.links.new(mul.outputs[0], density)
    else:  # Principled Volume: Density multiplies the Density Attribute
        nt.links.new(keep.outputs[0], density)
    halo = _volume_material().HALO_DENSITY
    if halo in nt.nodes:
        nt.links.new(keep.outputs[0], nt.nodes[halo].inputs[1])


def add_vdb(scene, path, mat, location, scale=1.0, rot_z=0.0, name="Cloud"):
    """A Volume object reading `path` with material `mat`; scale: one factor or (x, y, z)."""
    import pathlib

    import bpy

    vol = bpy.data.volumes.new(name)
    vol.filepath = str(pathlib.Path(path).resolve())
    vol.grids.load()
    vol.materials.append(mat)
    obj = bpy.data.objects.new(name, vol)
    obj.location = location
    obj.scale = tuple(scale) if isinstance(scale, (tuple, list)) else (scale, scale, scale)
    obj.rotation_euler = (0.0, 0.0, rot_z)
    scene.collection.objects.link(obj)
    return obj
