"""The gallery's scene geometry (scripts/gallery_scene.py; no Blender needed): companion
clouds each have their own proportions within the stated ranges (exact bounds), and side-on none
stands on another of similar picture size (the round-5 "snowman": a far cloud under a near one)
while clusters overlap side by side (not the evenly spaced field of rounds 21-22)."""
import json
import math
import random
import sys

import cloudgen_native as cn
import numpy as np
import pytest
from test_cli import REPO_ROOT

sys.path.insert(0, str(REPO_ROOT / "scripts"))
import gallery_scene as gs  # noqa: E402

COMPACT = sorted(gs.COMPANIONS)


def _values(name):
    return gs.widened(name, dict(cn.defaults(), **cn.presets()[name]["params"]))


def _picture_rect(values, x, y, scale, base, pitch):
    """The picture rectangle of a cloud baked from `values`, scaled by `scale` (x, y, z) and
    standing at (x, y) on `base` (None: a corner behind the camera)."""
    bx, by, bz = values["box_size"]
    z0, z1 = gs.vertical_extent(values)
    return gs._screen_rect(x, y, 0.5 * np.hypot(bx * scale[0], by * scale[1]), base, bz * scale[2] * (z1 - z0), pitch)


@pytest.mark.parametrize("name", COMPACT)
@pytest.mark.parametrize("view", ["side", "below"])
def test_companions_vary_and_do_not_stack(name, view):
    values = _values(name)
    variants = [gs.companion_values(name, k) for k in range(len(gs.COMPANION_VARIANTS))]
    centre, _, pitch, _ = gs.compact_view(name, values, view, 640, 360)
    placed = gs.companions(name, values, centre, view, 640, 360, random.Random(f"{name}-{view}"))
    assert len(placed) == gs.companion_count(name, view), (name, view, len(placed))
    lo, hi = gs.COMPANIONS[name][2]
    aspects = set()
    for _, _, _, (sx, sy, sz), _ in placed:
        assert lo * 0.75 <= min(sx, sy) and max(sx, sy) <= hi * 1.5 and lo * 0.45 <= sz <= hi * 1.1, (sx, sy, sz)
        aspects.add((round(sx / sz, 4), round(sy / sz, 4)))
    assert len(aspects) == len(placed), f"{name} {view}: companions share proportions {aspects}"
    base = gs.km(gs.BASE_KM.get(name, 1.2))
    extents = [gs.vertical_extent(v) for v in variants]
    for i, (_, _, z, (_, _, sz), _) in enumerate(placed):  # every variant's lowest point on the base (1e-9)
        z0 = extents[i % len(variants)][0]
        bottom = z - (0.5 - z0) * variants[i % len(variants)]["box_size"][2] * sz
        assert abs(bottom - base) < 1e-9, (name, view, i, bottom, base)
    rects = []  # in both views none stands on another in the picture (from below: a "mushroom")
    for i, (x, y, _, scale, _) in enumerate(placed):
        rect = _picture_rect(variants[i % len(variants)], x, y, scale, base, pitch)
        if rect is None:  # a corner behind the camera: not in the picture's plane
            continue
        assert not any(gs._rects_stack(rect, q) for q in rects), (name, view, (x, y), rect)
        rects.append(rect)
    if view == "side":
        # banks: at least 60 % of the companions overlap another in the picture (exact count;
        # the evenly spaced field of rounds 5-22 had 0 %, 13 % and 40 % for the cumulonimbus,
        # congestus and cumulus, the clustered one 98 %, 92 % and 88 %)
        banked = sum(any(gs.rects_overlap(a, b) for j, b in enumerate(rects) if j != i) for i, a in enumerate(rects))
        assert banked >= 0.6 * len(rects), (name, view, banked, len(rects))


@pytest.mark.parametrize("name", COMPACT)
def test_below_companions_are_in_the_picture(name):
    """From below every companion reaches into the 24 mm frame and none nearer than the main
    cloud overlaps its picture rectangle (exact geometry; until round 27 the frame held 7 of the
    cumulus's 24 companions and none of the congestus's 20), and the field spreads over the
    frame: companions left and right of the middle, and more than one distance (far ones under
    near ones)."""
    values = _values(name)
    variants = [gs.companion_values(name, k) for k in range(len(gs.COMPANION_VARIANTS))]
    centre, _, pitch, lens = gs.compact_view(name, values, "below", 640, 360)
    tx, ty = gs.tans(lens, 640, 360)
    base = gs.km(gs.BASE_KM.get(name, 1.2))
    main_rect = _picture_rect(values, centre[0], centre[1], (1.0, 1.0, 1.0), base, pitch)
    placed = gs.companions(name, values, centre, "below", 640, 360, random.Random(f"{name}-below"))
    us, ds = [], []
    for i, (x, y, _, scale, _) in enumerate(placed):
        rect = _picture_rect(variants[i % len(variants)], x, y, scale, base, pitch)
        assert rect is not None and gs.rects_overlap(rect, (-tx, tx, -ty, ty)), (name, i, (x, y), rect)
        assert not (y < centre[1] and gs.rects_overlap(rect, main_rect)), (name, i, (x, y), rect, main_rect)
        us.append(0.5 * (rect[0] + rect[1]))
        ds.append(y / centre[1])
    assert min(us) < -0.3 * tx and max(us) > 0.3 * tx, (name, sorted(round(u / tx, 2) for u in us))
    assert max(ds) > 1.5 * min(ds), (name, sorted(round(v, 2) for v in ds))


def _silhouette(values):
    """Where a companion bake has density, seen side-on: the union of 9 x-z cuts, 64 x 32."""
    cuts = [cn.slice(values, "y", float(y), 64, 32) > 0 for y in np.linspace(0.1, 0.9, 9)]
    return np.logical_or.reduce(cuts)


def test_companion_bodies_differ():
    """The companion variants are different bodies, not one dome with other noise: side-on
    silhouettes overlap (intersection over union) at most 0.86 for any pair and 0.75 in the
    median pair. The six variants of rounds 12-24, which changed only the noise, overlapped
    0.83-0.89, median 0.86 ("cloned cotton-balls", "pills", "stickers"); these: 0.57-0.84,
    median 0.65."""
    for name in COMPACT:
        sil = [_silhouette(gs.companion_values(name, i)) for i in range(len(gs.COMPANION_VARIANTS))]
        pairs = {(i, j): (sil[i] & sil[j]).sum() / (sil[i] | sil[j]).sum()
                 for i in range(len(sil)) for j in range(i + 1, len(sil))}
        worst = max(pairs, key=pairs.get)
        assert pairs[worst] <= 0.86, f"{name}: variants {worst} overlap {pairs[worst]:.2f} side-on"
        median = float(np.median(list(pairs.values())))
        assert median <= 0.75, f"{name}: median overlap {median:.2f}: {pairs}"


def test_stacking_rule():
    """_rects_stack (exact): side by side on one base line overlapping is a bank (allowed); one
    over the other is a stack; much smaller behind passes; apart never stacks."""
    near = (-1.0, 1.0, 0.0, 1.0)
    assert not gs._rects_stack(near, (0.5, 2.5, 0.05, 1.05))        # one bank
    assert gs._rects_stack(near, (0.0, 2.0, -0.6, 0.4))             # a cloud under another
    assert not gs._rects_stack(near, (0.0, 0.5, -0.3, 0.2))         # 4x narrower: behind it
    assert not gs._rects_stack(near, (3.0, 5.0, -0.6, 0.4))         # apart


def test_file_numbers_do_not_depend_on_the_run():
    """A file's number depends only on (type, view, sun) and the seed: two runs into one
    folder with different --types or --shots never share a number (exact)."""
    import gallery

    types = sorted(cn.presets())
    both = dict(gallery.file_numbers(types, types, [("side", "low"), ("below", "high")], 0))
    below = dict(gallery.file_numbers(types, ["cirrostratus"], [("below", "high")], 0))
    side = dict(gallery.file_numbers(types, ["stratus"], [("side", "low")], 0))
    assert below == {("cirrostratus", "below", "high"): both[("cirrostratus", "below", "high")]}
    assert side == {("stratus", "side", "low"): both[("stratus", "side", "low")]}
    assert len(set(both.values())) == len(both) == 2 * len(types)


def test_layers_are_the_sheets_not_the_flat_boxes():
    """The cumulonimbus's box is wider than 3.3 times its height (for its anvil) and is still a
    compact cloud: baked whole and seen from its side, not in rings overhead (it was, for a run)."""
    for name, preset in cn.presets().items():
        values = dict(cn.defaults(), **preset["params"])
        assert gs.is_layer(values) == (values["sheet"] >= 0.5), name
    cb = dict(cn.defaults(), **cn.presets()["cumulonimbus"]["params"])
    assert not gs.is_layer(cb) and cb["box_size"][2] < 0.3 * cb["box_size"][0]


def test_side_view_centres_the_leaning_anvil():
    """The anvil leans downwind (+x): the side view moves the storm so that its own middle, not its
    box's, is in the middle of the frame (to the slice's 1/192 of the box); the symmetric types stay."""
    for name in COMPACT:
        values = _values(name)
        middle = gs.horizontal_middle(values)
        centre, _, _, _ = gs.compact_view(name, values, "side", 640, 360)
        if name == "cumulonimbus":
            assert middle > 0.55, middle
            assert centre[0] == pytest.approx((0.5 - middle) * values["box_size"][0]), (name, middle, centre)
        else:
            assert abs(middle - 0.5) <= 0.05 and centre[0] == 0.0, (name, middle, centre)


@pytest.mark.parametrize("name", ["cumulus", "cumulus_congestus"])
def test_cumuliform_from_below_shows_its_towers(name):
    """From below, the congestus (from 4 km at 30 degrees) and the cumulus (at 35 degrees) are
    seen so that the summit (the top of the slice's extent, over the box's centre) is inside the
    frame, with a margin of 5 degrees, and the base in the lower half, seen at under 40 degrees:
    the dome shows over a foreshortened base (from right under it, round 6, the congestus's base
    filled the frame and it read as a cumulus; the cumulus at 55 degrees, round 14, read as a
    round dark disc)."""
    import math

    values = _values(name)
    centre, cam, pitch, lens = gs.compact_view(name, values, "below", 640, 360)
    _, ty = gs.tans(lens, 640, 360)
    half = math.degrees(math.atan(ty))
    z0, z1 = gs.vertical_extent(values)
    bz = values["box_size"][2]
    top = centre[2] + (z1 - 0.5) * bz
    base = centre[2] + (z0 - 0.5) * bz
    top_elevation = math.degrees(math.atan2(top - cam[2], centre[1] - cam[1]))
    base_elevation = math.degrees(math.atan2(base - cam[2], centre[1] - cam[1]))
    assert top_elevation < pitch + half - 5.0, (top_elevation, pitch, half)
    assert pitch - half < base_elevation < min(pitch, 40.0), (name, base_elevation, pitch, half)


@pytest.mark.parametrize("name", ["altostratus", "cirrostratus"])
def test_sun_in_the_veils_side_frame(name):
    """Side-on under the low sun the veils' sun is inside the frame, at least 3 degrees from
    each edge (the frame: 35 mm, 640 x 360, the horizon 12 % up), and no other side shot has it
    there."""
    import math

    import gallery

    elevation, azimuth = gallery.sun_direction(name, "side", "low", compact=False)
    tx, ty = gs.tans(gs.SIDE_LENS, 640, 360)
    pitch = gs.pitch_for_horizon(ty)
    half_x, half_y = math.degrees(math.atan(tx)), math.degrees(math.atan(ty))
    assert abs(azimuth) <= half_x - 3, (name, azimuth, half_x)
    assert pitch - half_y + 3 <= elevation <= pitch + half_y - 3, (name, elevation, pitch, half_y)
    for other in ("stratus", "nimbostratus", "cirrus", "cumulus"):
        _, az = gallery.sun_direction(other, "side", "low", compact=other == "cumulus")
        assert abs(az) > half_x, (other, az)


def test_thin_layer_levels_are_box_filtered_where_the_layer_is_resolved():
    # A level is baked with --supersample 2 where the layer spans 1 to THIN_LAYER_VOXELS voxels and
    # with 3 where it is thinner than a voxel (there the box filter samples the cell's part inside
    # the layer; point-sampled, the layer came out a whole voxel thick: 1.9x-7.4x its column,
    # tests/native/test_supersample.cpp); thicker, the point samples resolve it. Exact.
    values = _values("cirrocumulus")
    chosen = []
    for lv, res, _, _ in gs.layer_levels("cirrocumulus", values, 640):
        b = lv["box_size"]
        z_voxels = b[2] * res / max(b)
        k = gs.level_supersample(lv, res)
        chosen.append((round(z_voxels, 2), k))
        want = 3 if z_voxels < 1.0 else 2 if z_voxels < gs.THIN_LAYER_VOXELS else 1
        assert k == want, chosen
    assert [k for _, k in chosen] == [3, 3, 2, 2], chosen  # 0.5, 0.9, 1.8 and 6.6 voxels thick
    # the nimbostratus is thick in voxels at every level: point samples
    nb = _values("nimbostratus")
    assert all(gs.level_supersample(lv, res) == 1 for lv, res, _, _ in gs.layer_levels("nimbostratus", nb, 640))


def test_overcast_decks_reach_closer_to_the_horizon():
    # Overcast decks are widened until their far edge is OVERCAST_FAR_EDGE_DEG (0.3) above the
    # horizon, seen from the centre at ground level (1e-9 relative), with two more nested levels;
    # other layers keep FAR_EDGE_DEG (1) and NESTED_LEVELS. Each level's ring joins the next
    # (outer of level k+1 == inner of level k, exact) and the innermost has no hole.
    for name in ("stratus", "nimbostratus", "altostratus", "altocumulus"):
        values = _values(name)
        half = values["box_size"][0] / 2
        deg = math.degrees(math.atan(gs.km(gs.BASE_KM[name]) / half))
        want = gs.OVERCAST_FAR_EDGE_DEG if name in gs.OVERCAST else gs.FAR_EDGE_DEG
        assert deg == pytest.approx(want, rel=1e-9), (name, deg)
        levels = gs.layer_levels(name, values, 640)
        assert len(levels) == gs.NESTED_LEVELS + (gs.OVERCAST_EXTRA_LEVELS if name in gs.OVERCAST else 0), name
        for (_, _, inner, _), (_, _, _, outer) in zip(levels, levels[1:]):
            assert outer == inner, (name, inner, outer)
        assert levels[-1][2] == 0.0 and levels[0][3] is None, name


def test_companion_variants_are_valid_distinct_clouds():
    """Each companion variant is a valid parameter set over its preset (names and ranges checked
    by the module), the variants differ from each other, and each still makes a cloud: a
    central cross-section with density > 0 over at least 5 % of its cells."""
    assert len({json.dumps(v, sort_keys=True) for v in gs.COMPANION_VARIANTS}) == len(gs.COMPANION_VARIANTS)
    for name in COMPACT:
        seeds = set()
        for i, variant in enumerate(gs.COMPANION_VARIANTS):
            values = cn.resolve_params(gs.companion_values(name, i))
            preset_density = cn.presets()[gs.COMPANIONS[name][0]]["params"]["density"]
            want = {("density" if k == "density_scale" else k): (preset_density * v if k == "density_scale" else v)
                    for k, v in variant.items()}  # density_scale: that fraction of the preset's density
            assert all(np.allclose(values[k], v) for k, v in want.items()), (name, i, variant)
            seeds.add(values["seed"])
            cut = cn.slice(values, "y", 0.5, 64, 64)
            assert (cut > 0).mean() > 0.05, f"{name} variant {i} {variant}: {(cut > 0).mean():.3f} of the cut non-empty"
        assert len(seeds) == len(gs.COMPANION_VARIANTS), (name, seeds)


@pytest.mark.parametrize("name", COMPACT)
def test_side_field_reaches_toward_the_horizon(name):
    """Side-on the field runs out past half of COMPANION_FAR times the main cloud's distance
    (with 14 companions out to 8 times the sky under the main cloud was empty, round 13), and
    at least a third of the companions stand beyond 4 times it."""
    values = _values(name)
    centre, _, _, _ = gs.compact_view(name, values, "side", 640, 360)
    placed = gs.companions(name, values, centre, "side", 640, 360, random.Random(f"{name}-side"))
    ratios = [y / centre[1] for _, y, _, _, _ in placed]
    assert max(ratios) > 0.5 * gs.COMPANION_FAR, (name, max(ratios))
    assert sum(r > 4.0 for r in ratios) >= len(ratios) / 3, (name, sorted(round(r, 1) for r in ratios))


def test_glare_is_metered_down_and_sunny_frames_are_not():
    import gallery
    # Exact (closed form): no change up to GLARE_LIGHT (the twelve sunlit frames of round 15 read
    # 2.15-4.71), then the frame's light is brought down to GLARE_LIGHT; continuous at the bound.
    for light in (0.5, 2.15, 3.2, 4.71, gallery.GLARE_LIGHT):
        assert gallery.glare_compensation(light) == 0.0, light
    assert gallery.glare_compensation(2 * gallery.GLARE_LIGHT) == -1.0
    assert abs(gallery.glare_compensation(45.26) - math.log2(gallery.GLARE_LIGHT / 45.26)) < 1e-12
    assert gallery.glare_compensation(gallery.GLARE_LIGHT * 1.000001) < 0.0
    assert abs(gallery.glare_compensation(gallery.GLARE_LIGHT * 1.000001)) < 1e-5


def test_layer_levels_are_baked_whole(monkeypatch, tmp_path):
    """Each nested level of a layer is baked as its whole square (no --ring), so that no volume's
    boundary stands where its masked density is not zero: baked out to its ring's outer edge
    only, level 1's wall let the sun through behind it, a lit patch with a hard edge in the
    stratocumulus side-on (rounds 41-42, scripts/gallery.py's bake_all). Checked on the
    command lines bake_all would run (nothing is baked)."""
    import argparse

    import gallery

    commands = []
    monkeypatch.setattr(gallery.subprocess, "run", lambda cmd, check: commands.append(cmd))
    args = argparse.Namespace(size="640x360", resolution=256)
    values = _values("stratocumulus")
    baked = gallery.bake_all("stratocumulus", values, str(tmp_path), args)
    levels = gs.layer_levels("stratocumulus", values, 640)
    assert len(commands) == len(levels) == len(baked["levels"]), (len(commands), len(levels))
    for cmd, (_, res, _, _) in zip(commands, levels):
        assert "--ring" not in cmd, cmd
        assert cmd[cmd.index("--resolution") + 1] == str(res), (cmd, res)
    assert [(i, o) for _, i, o in baked["levels"]] == [(i, o) for _, _, i, o in levels]
