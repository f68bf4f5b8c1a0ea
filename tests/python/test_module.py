"""Tests of the cloudgen_native extension module (thin bindings over the C++ core).

Each test states its tolerance; failing asserts print the parameters involved.
Run: .venv/bin/python -m pytest -q tests/python/test_module.py
(CLOUDGEN_PYTHON_DIR=<build>/python selects another build; see conftest.py).
"""
import gc
import math
import os
import shutil
import subprocess
import sys
import threading
import time

import cloudgen_native as cn
import numpy as np
import pytest

KINDS = {"float": 1, "int": 1, "vector": 3, "curve": None}
F32 = np.float32


def decls():
    return {d["name"]: d for d in cn.parameters()}


def at_bound(which):
    """A params dict with every parameter at its declared min or max."""
    out = {}
    for d in cn.parameters():
        v = d[which]
        out[d["name"]] = v if d["count"] == 1 else [v] * d["count"]
    return out


CUMULUS = {"preset": "cumulus"}
PARAM_SETS = {
    "defaults": {},
    "cumulus": CUMULUS,
    "cumulus_curve_far": {"preset": "cumulus", "shape_mode": 1, "object_location": [1e5, -3e4, 250.0], "time": 12.5},
    "all_min": at_bound("min"),
    "all_max": at_bound("max"),
}


def box_of(params):
    return np.asarray(cn.resolve_params(params)["box_size"], dtype=F32)


def slice_points(box, axis, offset, width, height):
    """Local points of slice pixels, from grid.h's documented convention, in float32
    with the same operations as the core: columns along the first other axis (y for
    axis x, else x), rows along z (axis x, y) or y (axis z), row 0 at the top; pixel
    centres; generated g = (i + 1/2) / n, local p = (g - 1/2) * box."""
    column_axis = 1 if axis == 0 else 0
    row_axis = 1 if axis == 2 else 2
    cols = (np.arange(width, dtype=F32) + F32(0.5)) / F32(width)
    rows = F32(1.0) - (np.arange(height, dtype=F32) + F32(0.5)) / F32(height)
    g = np.empty((height, width, 3), dtype=F32)
    g[..., axis] = F32(offset)
    g[..., column_axis] = cols[None, :]
    g[..., row_axis] = rows[:, None]
    return ((g - F32(0.5)) * box).reshape(-1, 3)


# ------------------------------------------------------------ declarations ---


def test_parameters_are_the_declarations():
    # Tolerance: exact (structure and ranges of the table).
    params = cn.parameters()
    names = [d["name"] for d in params]
    assert len(names) == len(set(names)), f"duplicate keys in {names}"
    for d in params:
        assert set(d) == {"name", "label", "group", "kind", "count", "default", "min", "max", "soft_min",
                          "soft_max", "map", "unit", "help"}, d
        assert d["kind"] in KINDS, d
        assert KINDS[d["kind"]] in (None, d["count"]), d
        values = [d["default"]] if d["count"] == 1 else d["default"]
        assert len(values) == d["count"], d
        if d["kind"] == "int":
            assert all(type(v) is int for v in values + [d["min"], d["max"]]), d
        else:
            assert all(type(v) is float and math.isfinite(v) for v in values), d
        assert all(d["min"] <= v <= d["max"] for v in values), f"default outside [min, max]: {d}"
        assert d["min"] <= d["soft_min"] <= d["soft_max"] <= d["max"], f"soft range outside hard range: {d}"
        assert isinstance(d["map"], tuple) and len(d["map"]) == 2, d
        assert d["label"] and d["group"] and d["help"], d
    assert {"density", "cloud_scale", "box_size", "shape_curve", "object_location", "time"} <= set(names)


def test_defaults_match_declarations_and_resolve():
    # Tolerance: exact (same float32 values, same shortest repr).
    expected = {d["name"]: d["default"] for d in cn.parameters()}
    assert cn.defaults() == expected
    assert cn.resolve_params({}) == expected
    assert cn.resolve_params(None) == expected
    assert cn.resolve_params(cn.defaults()) == expected


def test_presets_within_declared_ranges():
    # Tolerance: exact (every preset value inside [min, max], all keys present).
    ds = decls()
    presets = cn.presets()
    assert "cumulus" in presets
    for name, preset in presets.items():
        assert isinstance(preset["description"], str) and preset["description"], name
        assert set(preset["params"]) == set(ds), name
        for key, value in preset["params"].items():
            d = ds[key]
            values = [value] if d["count"] == 1 else value
            assert len(values) == d["count"], (name, key, value)
            assert all(d["min"] <= v <= d["max"] for v in values), f"preset {name}: {key}={value} outside {d}"
        # The "preset" key of a params dict means exactly this preset.
        assert cn.resolve_params({"preset": name}) == preset["params"], name
        assert cn.resolve_params(preset["params"]) == preset["params"], name


def test_presets_material():
    # Tolerance: exact (known keys, numbers, colour of three values in [0, 1]).
    for name, preset in cn.presets().items():
        material = preset["material"]
        assert isinstance(material, dict), name
        known = {"anisotropy", "color", "step_rate", "halo", "backscatter", "side_scatter"}
        assert set(material) <= known, (name, material)
        assert isinstance(material.get("anisotropy", 0.0), float), (name, material)
        assert -1.0 <= material.get("anisotropy", 0.0) <= 1.0, (name, material)
        if "color" in material:
            assert len(material["color"]) == 3 and all(0.0 <= c <= 1.0 for c in material["color"]), name
    assert cn.presets()["cumulus"]["material"]["anisotropy"] == 0.5  # water clouds: docs/model.md section 10


def test_preset_key_then_overrides():
    # Tolerance: exact.
    base = cn.presets()["cumulus"]["params"]
    got = cn.resolve_params({"preset": "cumulus", "density": 0.25, "box_size": (1, 2, 3)})
    assert got == {**base, "density": 0.25, "box_size": [1.0, 2.0, 3.0]}, got


def test_version():
    assert isinstance(cn.__version__, str) and cn.__version__[0].isdigit(), cn.__version__


# ------------------------------------------------------------------ values ---


@pytest.mark.parametrize("name", ["defaults", "cumulus", "cumulus_curve_far"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_density_equals_slice(name, axis):
    # Tolerance: 0 (slice() and density() evaluate the same kernel at the same float32 points).
    params = PARAM_SETS[name]
    box = box_of(params)
    for offset, width, height in [(0.5, 23, 17), (0.3125, 16, 32), (0.0, 5, 7), (1.0, 3, 2)]:
        image = cn.slice(params, "xyz"[axis], offset, width, height)
        assert image.shape == (height, width) and image.dtype == np.float32
        values = cn.density(params, slice_points(box, axis, offset, width, height)).reshape(height, width)
        bad = np.argwhere(values != image)
        assert bad.size == 0, (f"params={params} axis={axis} offset={offset} size={width}x{height}: "
                               f"{len(bad)} pixels differ, first {bad[:3].tolist()}")
    assert image.max() >= 0


def test_slice_has_cloud_and_axis_spellings_agree():
    # Tolerance: exact (same call, different spelling of the axis).
    img = cn.slice(CUMULUS, "z", 0.3, 32, 24)
    assert img.max() > 0, "the cumulus cross-section is empty"
    for spelling in (2, "Z", np.int64(2)):
        assert np.array_equal(cn.slice(CUMULUS, spelling, 0.3, 32, 24), img), spelling
    lod = cn.slice(CUMULUS, "z", 0.3, 32, 24, lod=True)
    assert lod.shape == img.shape and np.all(np.isfinite(lod)) and np.all(lod >= 0)


@pytest.mark.parametrize("name", sorted(PARAM_SETS))
def test_density_nonnegative_finite_and_zero_outside_box(name):
    # Tolerance: exact (>= 0, finite; exactly 0 outside the box).
    params = PARAM_SETS[name]
    box = box_of(params)
    rng = np.random.default_rng(7)
    inside = (rng.random((20000, 3), dtype=np.float32) - F32(0.5)) * box
    values = cn.density(params, inside)
    assert np.all(np.isfinite(values)) and np.all(values >= 0), f"params={params}: min {values.min()}"
    # Outside: at least one coordinate beyond the half-extent (by 1 % to 10x).
    outside = (rng.random((5000, 3)) - 0.5) * box
    axis = rng.integers(0, 3, len(outside))
    sign = rng.choice([-1.0, 1.0], len(outside))
    outside[np.arange(len(outside)), axis] = sign * box[axis] * 0.5 * rng.uniform(1.01, 10.0, len(outside))
    out_values = cn.density(params, outside)
    assert np.all(out_values == 0), f"params={params}: non-zero density outside the box {outside[out_values != 0][:3]}"


def test_nonfinite_and_huge_points_give_zero():
    # Tolerance: exact. Points are positions, not parameters: NaN, Inf and far-away
    # points lie outside the box, where the density is 0 (documented in density()).
    points = [[np.nan, 0, 0], [0, np.inf, 0], [0, 0, -np.inf], [1e30, 0, 0], [-3e38, 3e38, 0]]
    assert np.array_equal(cn.density(CUMULUS, points), np.zeros(5, np.float32))


def test_density_linear_in_density_parameter():
    # Tolerance: relative 1e-6 (the kernel multiplies by density x 20 at the end).
    rng = np.random.default_rng(3)
    box = box_of(CUMULUS)
    points = (rng.random((4000, 3), dtype=np.float32) - F32(0.5)) * box
    ref = cn.density({**CUMULUS, "density": 0.5}, points)
    assert ref.max() > 0, "no cloud at the sample points"
    for k in (0.0, 0.125, 1.0, 3.0, 10.0):
        got = cn.density({**CUMULUS, "density": k}, points)
        np.testing.assert_allclose(got, ref * (k / 0.5), rtol=1e-6, atol=0,
                                   err_msg=f"params={CUMULUS} density={k}")


def test_points_dtype_and_layout_do_not_matter():
    # Tolerance: 0 (float64 copies of float32 values convert back exactly).
    rng = np.random.default_rng(11)
    box = box_of(CUMULUS)
    p32 = np.ascontiguousarray((rng.random((3001, 3), dtype=np.float32) - F32(0.5)) * box)
    ref = cn.density(CUMULUS, p32)
    big = np.zeros((3001, 7), dtype=np.float64)
    big[:, 2:5] = p32
    variants = {
        "float64": p32.astype(np.float64),
        "fortran float32": np.asfortranarray(p32),
        "column view float64": big[:, 2:5],
        "transposed view": np.ascontiguousarray(p32.T).T,
        "reversed": p32[::-1][::-1],
        "big-endian float64": p32.astype(">f8"),
        "nested list": p32.tolist(),
        "memoryview": memoryview(p32),
    }
    for name, points in variants.items():
        got = cn.density(CUMULUS, points)
        assert got.dtype == np.float32 and got.shape == (3001,), name
        assert np.array_equal(got, ref), f"{name}: params={CUMULUS}"
    stepped = np.repeat(p32, 2, axis=0)[::2]  # non-contiguous rows
    assert np.array_equal(cn.density(CUMULUS, stepped), ref)
    assert cn.density(CUMULUS, np.empty((0, 3))).shape == (0,)


def test_threads_do_not_change_density():
    # Tolerance: 0 (each point is evaluated independently).
    rng = np.random.default_rng(5)
    points = (rng.random((20000, 3), dtype=np.float32) - F32(0.5)) * box_of(CUMULUS)
    one = cn.density(CUMULUS, points, threads=1)
    assert np.array_equal(cn.density(CUMULUS, points, threads=2), one)
    assert np.array_equal(cn.density(CUMULUS, points), one)


def test_input_dict_not_modified():
    params = {"preset": "cumulus", "density": 0.3, "box_size": [1.0, 2.0, 3.0]}
    copy = {k: (list(v) if isinstance(v, list) else v) for k, v in params.items()}
    cn.density(params, np.zeros((4, 3)))
    cn.slice(params, "x", 0.5, 4, 4)
    assert params == copy


# -------------------------------------------------------------- bad input ---


def nudged(key, which):
    """The float32 just outside a declared bound."""
    d = decls()[key]
    direction = np.inf if which == "max" else -np.inf
    return float(np.nextafter(F32(d[which]), F32(direction)))


def range_text(key):
    """The accepted range as the core prints it: float32 bounds with 9 significant
    digits ("[0.0500000007, 1]") today, or the shortest form ("[0.05, 1]") — either
    is accepted."""
    d = decls()[key]
    return (f"[{float(F32(d['min'])):.9g}, {float(F32(d['max'])):.9g}]", f"[{d['min']:g}, {d['max']:g}]")


BAD_PARAMS = [
    # (params, must-appear-in-message list)
    ({"nonsense": 1.0}, ["nonsense"]),
    ({"Density": 0.5}, ["Density"]),
    ({"density": nudged("density", "max")}, ["density", range_text("density")]),
    ({"density": nudged("density", "min")}, ["density", range_text("density")]),
    ({"cloud_scale": nudged("cloud_scale", "min")}, ["cloud_scale", range_text("cloud_scale")]),
    ({"cloud_scale": nudged("cloud_scale", "max")}, ["cloud_scale", range_text("cloud_scale")]),
    ({"time": 1e300}, ["time", range_text("time")]),
    ({"seed": 10**400}, ["seed"]),
    ({"density": float("nan")}, ["density", range_text("density")]),
    ({"density": float("inf")}, ["density", range_text("density")]),
    ({"distortion": -float("inf")}, ["distortion", range_text("distortion")]),
    ({"box_size": [1.0, 2.0]}, ["box_size", range_text("box_size")]),
    ({"box_size": [1.0, 2.0, 3.0, 4.0]}, ["box_size"]),
    ({"box_size": [1.0, float("nan"), 3.0]}, ["box_size"]),
    ({"box_size": [1.0, 0.0, 3.0]}, ["box_size", range_text("box_size")]),
    ({"wind_direction": 1.0}, ["wind_direction"]),
    ({"wind_direction": "xyz"}, ["wind_direction"]),
    ({"shape_curve": [0.5] * 16}, ["shape_curve"]),
    ({"shape_curve": [0.5] * 16 + [1.5]}, ["shape_curve", range_text("shape_curve")]),
    ({"seed": 1.5}, ["seed", range_text("seed")]),
    ({"shape_mode": 2}, ["shape_mode", range_text("shape_mode")]),
    ({"density": True}, ["density"]),  # bool is refused for every numeric parameter
    ({"seed": np.bool_(True)}, ["seed"]),
    ({"density": "0.5"}, ["density"]),
    ({"density": None}, ["density"]),
    ({"density": [0.5]}, ["density"]),
    ({"preset": "nimbus"}, ["nimbus", "cumulus"]),
    ({"preset": 3}, ["preset"]),
    ({1: 0.5}, ["str"]),
    ([("density", 0.5)], ["params"]),
]


@pytest.mark.parametrize("params,needles", BAD_PARAMS, ids=[repr(p)[:40] for p, _ in BAD_PARAMS])
def test_bad_params_refused_naming_key(params, needles):
    # Tolerance: exact (error type and message contents).
    for call in (lambda: cn.density(params, np.zeros((1, 3))),
                 lambda: cn.slice(params, "x", 0.5, 4, 4),
                 lambda: cn.resolve_params(params)):
        with pytest.raises((ValueError, TypeError)) as info:
            call()
        message = str(info.value)
        for needle in needles:
            alternatives = needle if isinstance(needle, tuple) else (needle,)
            assert any(a in message for a in alternatives), f"params={params!r}: {needle!r} not in {message!r}"


def test_bounds_themselves_accepted():
    # Tolerance: exact (min and max as printed by parameters() are valid values).
    for which in ("min", "max"):
        params = at_bound(which)
        assert cn.resolve_params(params) == params, which
    numpyish = {"density": np.float32(0.3), "seed": np.int64(4), "box_size": np.array([1.0, 2.0, 3.0])}
    assert cn.resolve_params(numpyish)["seed"] == 4


BAD_SLICE = [
    # (axis, offset, width, height, argument named, error types)
    ("w", 0.5, 8, 8, "axis", ValueError),
    (3, 0.5, 8, 8, "axis", ValueError),
    (-1, 0.5, 8, 8, "axis", ValueError),
    (1.0, 0.5, 8, 8, "axis", TypeError),
    ("x", 1.5, 8, 8, "offset", ValueError),
    ("x", -0.01, 8, 8, "offset", ValueError),
    ("x", float("nan"), 8, 8, "offset", ValueError),
    ("x", "0.5", 8, 8, "offset", TypeError),
    ("x", 0.5, 0, 8, "width", ValueError),
    ("x", 0.5, 8193, 8, "width", ValueError),
    ("x", 0.5, 2.5, 8, "width", TypeError),
    ("x", 0.5, True, 8, "width", TypeError),
    ("x", 0.5, 8, 0, "height", ValueError),
    ("x", 0.5, 8, -5, "height", ValueError),
]


@pytest.mark.parametrize("axis,offset,width,height,name,error", BAD_SLICE)
def test_bad_slice_arguments(axis, offset, width, height, name, error):
    # Tolerance: exact (error type; message names the argument and its range).
    with pytest.raises(error) as info:
        cn.slice({}, axis, offset, width, height)
    message = str(info.value)
    assert name in message, f"axis={axis!r} offset={offset!r} size={width!r}x{height!r}: {message!r}"
    if name in ("width", "height"):
        assert "[1, 8192]" in message, message
    if name == "offset":
        assert "[0, 1]" in message, message


@pytest.mark.parametrize("points", [
    np.zeros(3), np.zeros((4, 2)), np.zeros((4, 4)), np.zeros((2, 3, 1)), [[0.0, 1.0], [2.0]], "abc", 5.0,
], ids=["(3,)", "(4,2)", "(4,4)", "(2,3,1)", "ragged", "str", "scalar"])
def test_bad_points_shape(points):
    # Tolerance: exact (ValueError stating the expected shape).
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        cn.density({}, points)


def test_bad_threads():
    with pytest.raises(ValueError, match="threads"):
        cn.density({}, np.zeros((1, 3)), threads=-1)
    with pytest.raises(TypeError):
        cn.density({}, np.zeros((1, 3)), bogus=1)


# ------------------------------------------------------------ the library ---


def test_module_is_abi3_and_links_no_vdb_oiio_tbb():
    # Tolerance: exact (file name and the dynamic dependencies listed by ldd).
    path = cn.__file__
    assert path.endswith(".abi3.so"), path
    if shutil.which("ldd") is None:
        pytest.skip("ldd not available")
    out = subprocess.run(["ldd", path], capture_output=True, text=True, check=True).stdout
    for lib in ("libopenvdb", "libOpenImageIO", "libtbb", "libpython", "libImath", "libboost"):
        assert lib not in out, f"{path} links {lib}:\n{out}"


@pytest.mark.parametrize("which", ["slice", "density"])
def test_gil_released(which):
    # Tolerance: none (counts only, no timing thresholds): the main thread must make
    # progress while the worker is inside the C call. With a 1 s switch interval no
    # thread is forced off the GIL during this test, so the worker keeps the GIL from
    # reading `before` until the call starts, and from its return until reading the
    # counter again (the main thread only takes the GIL when it is given up); any
    # progress measured across the call therefore proves that the call released it.
    points = np.zeros((400000, 3), dtype=np.float32)
    counter = [0]
    seen = {}
    started = threading.Event()

    def worker():
        started.set()
        before = counter[0]
        if which == "slice":
            seen["result"] = cn.slice(CUMULUS, "y", 0.5, 384, 384, threads=1)
        else:
            seen["result"] = cn.density(CUMULUS, points, threads=1)
        seen["progress"] = counter[0] - before

    old = sys.getswitchinterval()
    sys.setswitchinterval(1.0)
    try:
        thread = threading.Thread(target=worker)
        thread.start()
        started.wait()
        while thread.is_alive():
            counter[0] += 1
            time.sleep(0.0005)  # gives the GIL up, so the worker can take it back at once
        thread.join()
    finally:
        sys.setswitchinterval(old)
    assert "progress" in seen, "the worker failed"
    assert seen["progress"] > 0, f"main thread made no progress during {which}() (params={CUMULUS})"


def rss_bytes():
    """Resident set size now (Linux /proc), or None."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


def test_no_reference_leaks():
    # Bounds, over 10^4 rounds of every function (results and error paths):
    #  * live Python objects (sys.getallocatedblocks) grow by < 1000 blocks — a leaked
    #    reference to anything created per call (result array, dict, float, str,
    #    exception) would leave >= 10^4 blocks;
    #  * resident memory grows by < 32 MiB (generous; catches leaked array data and C++
    #    buffers: a leaked (16,) result or points copy per call alone is small, but the
    #    (5, 6) slices, dicts and exceptions of 10^4 rounds add up to > 32 MiB);
    #  * the arguments' reference counts are unchanged (exact).
    params = {"preset": "cumulus", "density": 0.4, "box_size": [1.0, 2.0, 3.0]}
    points = np.random.default_rng(1).random((16, 3)) - 0.5
    bad = {"density": 99.0}

    def round_():
        cn.parameters()
        cn.presets()
        cn.defaults()
        cn.resolve_params(params)
        cn.density(params, points)
        cn.density(params, points.tolist())
        cn.slice(params, "z", 0.5, 6, 5)
        for call in (lambda: cn.density(bad, points), lambda: cn.density(params, points[:, :2]),
                     lambda: cn.slice(params, "q", 0.5, 4, 4), lambda: cn.resolve_params({"seed": "1"})):
            try:
                call()
            except (ValueError, TypeError):
                pass

    for _ in range(200):
        round_()
    gc.collect()
    refs = (sys.getrefcount(params), sys.getrefcount(points), sys.getrefcount(bad),
            sys.getrefcount(params["box_size"]))
    blocks, rss = sys.getallocatedblocks(), rss_bytes()
    for _ in range(10000):
        round_()
    gc.collect()
    grown_blocks = sys.getallocatedblocks() - blocks
    assert grown_blocks < 1000, f"{grown_blocks} more live Python objects after 10^4 rounds (params={params})"
    if rss is not None:
        grown = rss_bytes() - rss
        assert grown < 32 * 2**20, f"resident memory grew by {grown} bytes over 10^4 rounds (params={params})"
    assert refs == (sys.getrefcount(params), sys.getrefcount(points), sys.getrefcount(bad),
                    sys.getrefcount(params["box_size"])), "argument reference counts changed"
    result = cn.density(params, points)
    assert sys.getrefcount(result) == 2  # our name + getrefcount's argument
