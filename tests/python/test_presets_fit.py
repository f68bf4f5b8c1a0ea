"""A compact cloud preset (not a sheet) fits inside its box: no density on any face of the box,
for several seeds, late in time with wind, and far from the origin. Until 2026-11-29 the
cumulus and the congestus overflowed their box's ceiling (the distortion lifts the dome above
h = 1), so the bake and the OSL box cut them flat: 20 % and 10 % of the top row of a central
cross-section was cloud, seen in the main job's render and the gallery as a flat-topped dome.
Tolerance: exact (the density on a face is 0). The heap presets also stand on a flat, full
base (FLAT_BASE: measured bounds, stated there)."""
import cloudgen_native as cn
import numpy as np
import pytest

COMPACT = sorted(name for name, p in cn.presets().items() if not p["params"].get("sheet", 0.0))
VARIANTS = [{"seed": s} for s in range(4)] + [
    {"time": 40.0, "wind_strength": 1.0, "wind_direction": [1.0, 0.3, 0.1]},
    {"object_location": [1234.5, -987.25, 3.0]},
]
RES = 96


def test_the_compact_presets_are_the_heap_clouds():
    assert {"cumulus", "cumulus_congestus", "cumulonimbus"} <= set(COMPACT), COMPACT


@pytest.mark.parametrize("name", COMPACT)
def test_compact_preset_has_no_density_on_its_box(name):
    base = dict(cn.defaults(), **cn.presets()[name]["params"])
    for variant in VARIANTS:
        values = dict(base, **variant)
        faces = {f"{axis}={offset}": cn.slice(values, axis, offset, RES, RES)
                 for axis in ("x", "y", "z") for offset in (0.0, 1.0)}
        touched = {face: round(float((cut > 0).mean()), 4) for face, cut in faces.items() if cut.max() > 0}
        assert not touched, f"{name} {variant}: cloud on the box's faces (fraction of each face) {touched}"
        inside = cn.slice(values, "y", 0.5, RES, RES)
        assert (inside > 0).mean() > 0.05, f"{name} {variant}: the central cut is nearly empty"


# the lowest fraction of the height in which the base reaches half the lower body's width, and
# the least share of that row's extent that is dense (over half the cut's median density), per
# heap preset; measured 2026-11-29 (four seeds): rise 0-0.005 for all three, dense 0.88-0.97
# (cumulus, congestus) and 0.54-0.77 (the storm, its rain-shaft column); a rounded base (the
# cumulus with a squared radius rising from 0 over its lowest 35 %) gives rise 0.055, dense 0.55
FLAT_BASE = {"cumulus": (0.02, 0.8), "cumulus_congestus": (0.02, 0.8), "cumulonimbus": (0.02, 0.45)}


def _base_rise_and_density(values, n=256):
    """(rise, dense) of a heap cloud's base from nine x-z cuts through its middle (y 0.3-0.7):
    rise, the height (fraction of the cloud's) from its lowest cloud row to the lowest row whose
    mean extent is half the widest extent of the lower half of the cloud; dense, the mean share
    of that row's extent with density over half the median density of the cuts' cloud."""
    cuts = np.array([cn.slice(values, "y", float(y), n, n) for y in np.linspace(0.3, 0.7, 9)])
    occ = cuts > 0
    rows = np.where(occ.any(axis=(0, 2)))[0]
    top, bottom = rows.min(), rows.max()  # row 0 is the box's top
    median = np.median(cuts[occ])

    def extent(row):
        widths = [np.ptp(np.where(o)[0]) + 1 for o in occ[:, row] if o.any()]
        return float(np.mean(widths)) if widths else 0.0

    extents = {r: extent(r) for r in range(top, bottom + 1)}
    height = bottom - top + 1
    widest = max(w for r, w in extents.items() if r >= top + height // 2)
    base = max(r for r, w in extents.items() if w >= 0.5 * widest)
    dense = [(c > 0.5 * median).sum() / (np.ptp(np.where(c > 0)[0]) + 1) for c in cuts[:, base] if (c > 0).any()]
    return (bottom - base) / height, float(np.mean(dense))


@pytest.mark.parametrize("name", sorted(FLAT_BASE))
def test_heap_preset_has_a_flat_full_base(name):
    """A heap cloud stands on a flat condensation base (the issue's hard floor): within 2 % of
    its height from its lowest point it is half as wide as its lower body, and that row is
    mostly dense, for four seeds. Side-on in the gallery the base still shows as a rounded
    sliver: it is seen from a few degrees below (docs/lighting.md)."""
    rise_max, dense_min = FLAT_BASE[name]
    base = dict(cn.defaults(), **cn.presets()[name]["params"])
    for seed in (None, 7, 42, 1234):
        values = base if seed is None else dict(base, seed=seed)
        rise, dense = _base_rise_and_density(values)
        assert rise <= rise_max and dense >= dense_min, (
            f"{name} seed {seed}: base reaches half width {rise:.3f} of the height up (at most {rise_max}), "
            f"dense share {dense:.2f} (at least {dense_min})")
