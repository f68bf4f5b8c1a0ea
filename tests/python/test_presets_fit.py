"""A compact cloud preset (not a sheet) fits inside its box: no density on any face of the box,
for several seeds, late in time with wind, and far from the origin. Until 2026-11-29 the
cumulus and the congestus overflowed their box's ceiling (the distortion lifts the dome above
h = 1), so the bake and the OSL box cut them flat: 20 % and 10 % of the top row of a central
cross-section was cloud, seen in the main job's render and the gallery as a flat-topped dome.
Tolerance: exact (the density on a face is 0)."""
import cloudgen_native as cn
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
