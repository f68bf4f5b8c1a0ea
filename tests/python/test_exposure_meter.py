"""The exposure meter's rule for a sun hidden by cloud (addon/exposure_meter.py; no Blender
needed): how much of the sun's direct light reaches the ground (sun_transmittance,
sunlit_share) and how the exposure moves from the sun's to the overcast's (overcast_weight,
blended_exposure).

- The ray geometry against exact answers: a box of constant extinction k, turned and moved, a
  ray toward a sun at elevation e through its whole thickness h gives exp(-k h / sin e); a ray
  that starts inside gives the rest of its way; one that misses, or points away, gives 1
  (tolerance 1e-6: midpoint sums of a constant are exact to rounding).
- The weight: 1 at and below SHARE_OVERCAST, 0 at and above SHARE_SUNNY, monotone and
  continuous between (no jump larger than 0.01 over a 1e-3 step in log share).
- The gallery's shots (scripts/gallery.py): its three overcasts take the overcast's exposure
  whole (weight 1), the compact clouds the sun's (weight 0) and the thin layers nearly the sun's
  (weight <= 0.15; the stratocumulus, 3-11 %, is the one layer the rule moves), so the add-on's
  physical rule and the gallery's grey-sky list agree; the share of each shot is printed."""
import math
import sys

import cloudgen_native as cn
import numpy as np
import pytest
from test_cli import REPO_ROOT

sys.path.insert(0, str(REPO_ROOT / "scripts"))
import gallery_scene as gs  # noqa: E402
import render_cloud  # noqa: E402

meter = render_cloud._addon_file("exposure_meter")
TOL = 1e-6


def _constant(k):
    """A density of k inside the box (cn.density gives 0 outside; here the box test is the
    caller's: sun_transmittance samples only inside)."""
    return lambda values, pts: np.full(len(pts), k)


def _turned(deg, at):
    """World -> model: a box turned by `deg` about z and centred at `at`."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    r = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # model -> world rotation
    m = np.eye(4)
    m[:3, :3] = r.T
    m[:3, 3] = -r.T @ np.asarray(at, dtype=float)
    return m


def _toward(elevation, azimuth):
    e, a = math.radians(elevation), math.radians(azimuth)
    return (math.sin(a) * math.cos(e), math.cos(a) * math.cos(e), math.sin(e))


@pytest.mark.parametrize("turn", [0.0, 30.0, 90.0])
@pytest.mark.parametrize("elevation", [10.0, 45.0, 89.0])
def test_transmittance_through_a_slab(turn, elevation):
    k, h = 0.7, 0.5
    values = {"box_size": [400.0, 300.0, h]}
    at = (3.0, -2.0, 5.0)
    clouds = [(values, _turned(turn, at))]
    points = np.array([[3.0, -2.0, 0.0], [10.0, 4.0, 0.0]])
    got = meter.sun_transmittance(clouds, points, _toward(elevation, 20.0), _constant(k))
    want = math.exp(-k * h / math.sin(math.radians(elevation)))
    assert np.allclose(got, want, rtol=0, atol=TOL), (turn, elevation, got, want)


def test_transmittance_from_inside_miss_and_away():
    k = 2.0
    values = {"box_size": [4.0, 4.0, 1.0]}
    clouds = [(values, _turned(0.0, (0.0, 0.0, 0.0)))]
    up = (0.0, 0.0, 1.0)
    inside = meter.sun_transmittance(clouds, [[0.5, 0.5, 0.2]], up, _constant(k))
    assert abs(inside[0] - math.exp(-k * 0.3)) < TOL, inside
    miss = meter.sun_transmittance(clouds, [[10.0, 0.0, -1.0]], up, _constant(k))
    away = meter.sun_transmittance(clouds, [[0.0, 0.0, 1.0]], up, _constant(k))
    below_down = meter.sun_transmittance(clouds, [[0.0, 0.0, -1.0]], (0.0, 0.0, -1.0), _constant(k))
    assert miss[0] == 1.0 and away[0] == 1.0 and below_down[0] == 1.0, (miss, away, below_down)
    two = meter.sun_transmittance(clouds * 2, [[0.0, 0.0, -1.0]], up, _constant(k))
    assert abs(two[0] - math.exp(-2 * k)) < TOL, two


def test_ground_disc():
    pts = meter.ground_disc((1.0, 2.0, 0.3), 5.0)
    r = np.hypot(pts[:, 0] - 1.0, pts[:, 1] - 2.0)
    assert len(pts) > 0.7 * meter.SHARE_GRID ** 2 and r.max() <= 5.0 and np.all(pts[:, 2] == 0.3), (len(pts), r.max())


def test_overcast_weight():
    lo, hi = meter.SHARE_OVERCAST, meter.SHARE_SUNNY
    assert meter.overcast_weight(0.0) == 1.0 and meter.overcast_weight(lo) == 1.0
    assert meter.overcast_weight(hi) == 0.0 and meter.overcast_weight(1.0) == 0.0
    logs = np.linspace(math.log(lo) - 0.5, math.log(hi) + 0.5, 3000)
    w = np.array([meter.overcast_weight(math.exp(x)) for x in logs])
    assert np.all(np.diff(w) <= 0.0), "the weight must fall as the share grows"
    assert np.abs(np.diff(w)).max() < 0.01, f"a jump of {np.abs(np.diff(w)).max():.4f}"
    sunny, light = -3.5, 2.0
    assert meter.blended_exposure(sunny, light, 1.0) == sunny
    assert abs(meter.blended_exposure(sunny, light, 0.0) - math.log2(meter.OVERCAST_KEY / light)) < TOL


def _gallery_share(name, view, sun):
    import gallery

    v0 = dict(cn.defaults(), **cn.presets()[name]["params"])
    values = gs.widened(name, v0)
    layer = gs.is_layer(v0)
    view_of = gs.layer_view if layer else gs.compact_view
    centre, cam, _, _ = view_of(name, values, view, 640, 360)
    elevation, azimuth = gallery.sun_direction(name, view, sun, compact=not layer)
    to_model = _turned(0.0, centre)
    points = meter.ground_disc(cam, gs.km(meter.SHARE_RADIUS_KM))
    return meter.sunlit_share([(values, to_model)], points, _toward(elevation, azimuth), cn.density)


@pytest.mark.parametrize("shot", [("side", "low"), ("below", "high")], ids=["side-low", "below-high"])
@pytest.mark.parametrize("name", sorted(cn.presets()))
def test_gallery_overcasts_take_the_overcast_exposure(name, shot):
    share = _gallery_share(name, *shot)
    weight = meter.overcast_weight(share)
    print(f"{name} {shot}: sunlit share {share:.3f}, overcast weight {weight:.2f}")
    if name in gs.OVERCAST:
        assert weight == 1.0, f"{name} {shot}: share {share:.3f} lets the sun's exposure in ({weight:.2f})"
    elif not gs.is_layer(dict(cn.defaults(), **cn.presets()[name]["params"])):
        assert weight == 0.0, f"{name} {shot}: share {share:.3f} takes the overcast's exposure ({weight:.2f})"
    elif name != "stratocumulus":  # the thin layers stay (nearly) sunny: docs/addon.md's shares
        assert weight <= 0.15, f"{name} {shot}: share {share:.3f} moves a sunny layer's exposure ({weight:.2f})"
