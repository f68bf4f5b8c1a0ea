"""The accuracy bench's measuring tools (bench/accuracy): error measures, the
Pareto front and its knee, and the report. Tiny known cases only; no timing."""
import json
import math
import struct

import common
import numpy as np
import pytest
from accuracy import analysis, metrics, pareto, report

# ------------------------------------------------------------ field error --


def test_field_error_constant_offset_is_exact():
    exact = np.linspace(0.0, 2.0, 101)
    approx = exact + 0.1
    got = metrics.field_error(approx, exact)
    # |d| = 0.1 everywhere, range 2 -> rms = max = 0.05 (tolerance 1e-12)
    for key, want in (("rms", 0.05), ("max", 0.05), ("range", 2.0)):
        assert abs(got[key] - want) < 1e-12, f"{key}: got {got[key]!r}, want {want} (exact=linspace(0,2,101), +0.1)"


def test_field_error_single_spike():
    exact = np.array([[0.0, 1.0], [2.0, 3.0]])
    approx = exact.copy()
    approx[1, 0] += 0.3
    got = metrics.field_error(approx, exact)
    # rms = sqrt(0.09 / 4) / 3 = 0.05, max = 0.3 / 3 = 0.1 (tolerance 1e-12)
    assert abs(got["rms"] - 0.05) < 1e-12, f"rms {got} for approx={approx.tolist()} exact={exact.tolist()}"
    assert abs(got["max"] - 0.1) < 1e-12, f"max {got} for approx={approx.tolist()} exact={exact.tolist()}"


def test_field_error_zero_range_is_absolute_not_nan():
    exact = np.full(5, 2.0)
    approx = exact + 0.25
    got = metrics.field_error(approx, exact)
    # a constant exact field: range 0, errors divided by 1 -> 0.25 (tolerance 1e-12), never NaN
    assert got["range"] == 0.0, f"range {got}"
    assert all(math.isfinite(v) for v in got.values()), f"non-finite in {got}"
    assert abs(got["rms"] - 0.25) < 1e-12 and abs(got["max"] - 0.25) < 1e-12, f"{got} for exact=2, approx=2.25"
    same = metrics.field_error(exact, exact)
    assert same["rms"] == 0.0 and same["max"] == 0.0, f"identical constant fields gave {same}"


def test_field_error_rejects_shape_mismatch():
    with pytest.raises(ValueError, match=r"approx has shape \(3,\) but exact has shape \(4,\)"):
        metrics.field_error(np.zeros(3), np.zeros(4))


@pytest.mark.parametrize("bad", ["approx", "exact"])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_field_error_rejects_non_finite_naming_the_argument(bad, value):
    a, e = np.linspace(0, 1, 4), np.linspace(0, 1, 4)
    (a if bad == "approx" else e)[2] = value
    with pytest.raises(ValueError, match=rf"^{bad}: 1 non-finite"):
        metrics.field_error(a, e)


# ------------------------------------------------------------ image error --


def test_image_rmse_known_difference_ignores_alpha():
    ref = np.zeros((4, 5, 4))
    test = ref.copy()
    test[..., 1] = 0.2   # green off by 0.2 everywhere
    test[..., 3] = 0.9   # alpha differs: ignored
    got = metrics.image_rmse(test, ref)
    want = math.sqrt(0.04 / 3)  # one channel of three (tolerance 1e-12)
    assert abs(got - want) < 1e-12, f"rmse {got!r}, want {want!r} (G +0.2, alpha +0.9 ignored)"
    assert metrics.image_rmse(test[..., :3], ref) == pytest.approx(want, abs=1e-12), "RGB vs RGBA mix"


def test_image_rmse_rejects_bad_shapes():
    with pytest.raises(ValueError, match="test is 5x4 pixels but ref is 4x4"):
        metrics.image_rmse(np.zeros((4, 5, 3)), np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match="ref: expected an HxWx3 or HxWx4 image"):
        metrics.image_rmse(np.zeros((4, 4, 3)), np.zeros((4, 4)))


def test_srgb_encode_known_values():
    x = np.array([-1.0, 0.0, 0.002, 0.5, 1.0, 7.0])
    got = metrics.srgb_encode(x)
    want = np.array([0.0, 0.0, 0.02584, 0.7353569831, 1.0, 1.0])  # clipped; 12.92 x; 1.055 x^(1/2.4) - 0.055
    assert np.allclose(got, want, atol=1e-6, rtol=0), \
        f"srgb_encode({x.tolist()}) = {got.tolist()}, want {want.tolist()} (tolerance 1e-6)"


def test_flip_identical_zero_different_positive_and_symmetric():
    rng = np.random.default_rng(1)
    a = rng.random((24, 32, 3)) * 0.8
    b = np.clip(a + rng.normal(0.0, 0.05, a.shape), 0.0, None)
    same = metrics.image_flip(a, a)
    ab, ba = metrics.image_flip(b, a), metrics.image_flip(a, b)
    assert abs(same) < 1e-7, f"FLIP of identical images {same!r} (tolerance 1e-7)"
    assert ab > 0.01, f"FLIP of noise sigma 0.05 is {ab!r}, expected > 0.01"
    # LDR-FLIP is symmetric by construction (see image_flip's docstring): tolerance 1e-6
    assert abs(ab - ba) < 1e-6, f"FLIP(b, a)={ab!r} vs FLIP(a, b)={ba!r}"
    flat_a, flat_b = np.full((8, 8, 3), 0.5), np.full((8, 8, 3), 0.25)
    assert metrics.image_flip(flat_b, flat_a) > 0.1, "flat 0.25 vs 0.5 should differ clearly (> 0.1)"
    # values above 1 are clipped before FLIP: 2.0 vs 3.0 is no difference (tolerance 1e-7)
    over = metrics.image_flip(np.full((8, 8, 3), 3.0), np.full((8, 8, 3), 2.0))
    assert abs(over) < 1e-7, f"FLIP of 3.0 vs 2.0 after clipping is {over!r}"


def test_noise_floor_halves_the_seed_difference():
    rng = np.random.default_rng(7)
    truth = rng.random((64, 64, 3)) * 0.5 + 0.1
    a = truth + rng.normal(0.0, 0.02, truth.shape)
    b = truth + rng.normal(0.0, 0.02, truth.shape)
    got = metrics.noise_floor(a, b)
    assert got["noise_rmse"] == pytest.approx(metrics.image_rmse(a, b), abs=1e-15), f"{got}"
    assert got["reference_rmse"] == pytest.approx(got["noise_rmse"] / 2, abs=1e-15), f"{got}"
    assert got["noise_flip"] > 0, f"{got}"
    actual = metrics.image_rmse((a + b) / 2, truth)  # the reference's real error
    # statistical: 12288 samples per estimate, relative spread ~1 %; tolerance 5 %
    assert abs(got["reference_rmse"] / actual - 1) < 0.05, f"estimate {got['reference_rmse']} vs actual {actual}"


# ------------------------------------------------------------------- EXR --


def write_exr_none(path, rgb):
    """A minimal uncompressed scanline OpenEXR (FLOAT B, G, R channels) for rgb (HxWx3, row 0 = top)."""
    h, w, _ = rgb.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<4i", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + attr("channels", "chlist", chlist)
              + attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    lines = []
    for y in range(h):
        data = b"".join(rgb[y, :, c].astype("<f4").tobytes() for c in (2, 1, 0))
        lines.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * h
    table = b""
    for line in lines:
        table += struct.pack("<Q", offset)
        offset += len(line)
    path.write_bytes(header + table + b"".join(lines))


def known_image():
    h, w = 3, 5
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    return np.stack([x * 0.5, y * 2.0 + 0.25, np.where((x == 0) & (y == 0), 3.5, 0.1)], axis=-1).astype(np.float32)


def test_load_exr_uncompressed_exact(tmp_path):
    want = known_image()
    path = tmp_path / "known.exr"
    write_exr_none(path, want)
    info = metrics.exr_header(path)
    assert info["compression"] == "NONE" and info["channels"] == ["B", "G", "R"], f"header {info}"
    got = metrics.load_exr(path)
    assert got.shape == (3, 5, 3) and got.dtype == np.float32, f"{got.shape} {got.dtype}"
    assert np.array_equal(got, want), f"loaded\n{got}\nwant (row 0 = top)\n{want}"


def test_load_exr_rejects_non_exr(tmp_path):
    path = tmp_path / "not.exr"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(64))
    with pytest.raises(ValueError, match="not an OpenEXR file"):
        metrics.load_exr(path)
    with pytest.raises(FileNotFoundError):
        metrics.load_exr(tmp_path / "missing.exr")


@pytest.mark.parametrize("codec", ["ZIP", "DWAA"])  # ZIP: flip_evaluator's loader; DWAA: the bpy fallback
def test_load_exr_written_by_blender(tmp_path, codec):
    bpy = pytest.importorskip("bpy")
    want = known_image()
    h, w, _ = want.shape
    img = bpy.data.images.new("exr_test", w, h, alpha=True, float_buffer=True)
    rgba = np.concatenate([want, np.ones((h, w, 1), np.float32)], axis=-1)[::-1]  # Blender: row 0 = bottom
    img.pixels.foreach_set(np.ascontiguousarray(rgba).ravel())
    scene = bpy.data.scenes.new("exr_test")
    fmt = scene.render.image_settings
    fmt.file_format, fmt.color_depth, fmt.exr_codec = "OPEN_EXR", "32", codec
    path = tmp_path / f"blender_{codec}.exr"
    img.save_render(str(path), scene=scene)
    bpy.data.images.remove(img)
    bpy.data.scenes.remove(scene)
    assert metrics.exr_header(path)["compression"] == codec
    got = metrics.load_exr(path)
    # float 32 ZIP is lossless; DWAA keeps float channels exact too (tolerance 1e-5 absolute)
    assert got.shape == want.shape and np.allclose(got, want, atol=1e-5, rtol=0), f"{codec}: got\n{got}\nwant\n{want}"


# ---------------------------------------------------------------- Pareto --


def P(name, t, e, **kw):
    return dict(name=name, time_s=t, flip=e, **kw)


def names(points):
    return [p["name"] for p in points]


def test_pareto_dominated_and_trade_off():
    pts = [P("slow_bad", 5.0, 0.3), P("fast_good", 1.0, 0.1)]
    assert names(pareto.pareto_front(pts)) == ["fast_good"], f"one dominates: {pts}"
    pts = [P("slow_good", 5.0, 0.1), P("fast_bad", 1.0, 0.3)]
    assert names(pareto.pareto_front(pts)) == ["fast_bad", "slow_good"], f"trade-off, sorted by cost: {pts}"


def test_pareto_ties():
    pts = [P("a", 1.0, 0.2), P("dup_of_a", 1.0, 0.2), P("same_cost_worse", 1.0, 0.3),
           P("same_error_slower", 2.0, 0.2), P("b", 3.0, 0.1)]
    got = names(pareto.pareto_front(pts))
    assert got == ["a", "b"], f"ties: first of identical kept, equal cost/error losers dropped; got {got} for {pts}"


def test_pareto_skips_missing_errors_and_custom_keys():
    pts = [P("none", 0.5, None), P("nan", 0.6, float("nan")), {"name": "absent", "time_s": 0.1},
           P("ok", 2.0, 0.2), P("no_time", None, 0.01)]
    assert names(pareto.pareto_front(pts)) == ["ok"], f"missing/NaN cost or error skipped: {pts}"
    assert pareto.pareto_front([P("x", 1.0, None)]) == [], "all missing -> empty front"
    custom = [{"name": "p", "c": 1, "e": 2}, {"name": "q", "c": 2, "e": 1}, {"name": "r", "c": 3, "e": 3}]
    assert names(pareto.pareto_front(custom, cost="c", error="e")) == ["p", "q"], f"{custom}"


def test_knee_of_an_l_shaped_front_is_the_corner():
    front = [P("end_fast", 1.0, 1.0), P("corner", 2.0, 0.05), P("end_slow", 1000.0, 0.0)]
    k = pareto.knee(list(reversed(front)))
    assert k is not None and k["name"] == "corner", f"knee {k} of {front}"
    assert pareto.knee(front[:2]) is None, "two points have no knee"
    on_line = [P("a", 1.0, 1.0), P("b", 10.0, 0.5), P("c", 100.0, 0.0)]  # straight in log-cost
    assert pareto.knee(on_line) is None, f"collinear front in log cost has no knee: {on_line}"


# ---------------------------------------------------------------- report --


def point(knob, setting, t, flip, rmse, bake=0.5, blender="4.5", **kw):
    return dict(knob=knob, setting=setting, label=f"{knob}:{setting}", blender=blender, render_s=t - bake,
                bake_s=bake, time_s=t, peak_mib=100.0, file_mib=2.0, rmse=rmse, flip=flip, **kw)


def synthetic():
    pts = [point("bake_resolution", "64", 2.0, 0.05, 0.005, field_rms=0.01, field_max=0.2),
           point("bake_resolution", "256", 8.0, 0.02, 0.002),
           point("camera_aware", "ppv=1", 3.0, 0.015, None),
           point("camera_aware", "ppv=2", 1.5, 0.06, 0.006),
           point("tier", "draft", 1.0, 0.1, 0.01), point("tier", "final", 20.0, 0.012, 0.0012),
           {"knob": "preview_resolution", "setting": "128", "render_s": 0.04, "field_rms": 0.02}]
    machine = {"cpu_model": "Test CPU", "nproc": 2, "mem_total_gib": 3.5, "load_average": [1.0, 0.5, 0.25]}
    return {"machine": machine, "blender": {"4.5": "4.5.15"},
            "settings": {"image_size": [32, 24], "runs_per_point": 2},
            "scenes": {"cumulus": {"reference": {"samples": 64, "seeds": [1, 2], "noise_rmse": 0.002,
                                                 "noise_flip": 0.01}, "points": pts},
                       "partial": {"points": [{"knob": "samples", "setting": "16"}]}}}


def test_camera_aware_equal_error_time():
    rows = {r["cam"]["setting"]: r for r in analysis.camera_rows(synthetic())}
    r = rows["ppv=2"]  # 64 (2 s, FLIP 0.05, RMSE 0.005) is as good on both: the measured match
    assert r["time"] == 2.0 and r["how"].startswith("measured") and r["ratio"] == 2.0 / 1.5, f"{r}"
    r = rows["ppv=1"]  # FLIP 0.015, no RMSE: better than every uniform bake -> extrapolated from 64 and 256
    # to the camera-aware error + EQUAL_ERROR (3 %): log t = log 2 + (target - 0.05) / (0.02 - 0.05) * log 4
    target = 0.015 * (1 + analysis.EQUAL_ERROR)
    want = 2.0 * 4.0 ** ((target - 0.05) / (0.02 - 0.05))  # relative tolerance 1e-9
    assert r["time"] == pytest.approx(want, rel=1e-9) and "extrapolated" in r["how"], f"{r}"
    assert r["ratio"] == pytest.approx(want / 3.0, rel=1e-9), f"{r}"
    uniform = [p for p in synthetic()["scenes"]["cumulus"]["points"] if p["knob"] == "bake_resolution"]
    t, how = analysis.time_at_error(uniform, "flip", 0.03)  # bracketed by 64 (0.05) and 256 (0.02)
    assert t == pytest.approx(2.0 * 4.0 ** (2.0 / 3.0), rel=1e-9) and "interpolated" in how, f"{t} {how}"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    d = tmp_path_factory.mktemp("report")
    docs = d / "docs" / "accuracy.md"
    docs.parent.mkdir()
    docs.write_text("# Mine\n\nHand text before.\n\n<!-- generated:start -->\nstale\n<!-- generated:end -->\n\n"
                    "Hand text after.\n")
    results = d / "accuracy.json"
    results.write_text(json.dumps(synthetic()))
    assert report.main(["--results", str(results), "--docs", str(docs), "--images", str(d / "docs/images")]) == 0
    return d, docs


def test_report_markdown_keeps_hand_text(written):
    d, docs = written
    text = docs.read_text()
    assert text.count("<!-- generated:start -->") == 1 and text.count("<!-- generated:end -->") == 1, text
    assert text.startswith("# Mine\n\nHand text before.\n") and text.endswith("Hand text after.\n"), text
    assert "stale" not in text, "old generated text must be replaced"
    for want in ("## Method", "**Machine:** Test CPU (2 cores, 3.5 GiB); load average before the sweep 1, 0.5, 0.25",
                 "## Quality tiers", "tier:draft", "## Camera-aware", "×",
                 "bake_resolution:256", "0.01 / 0.2", "images/pareto_cumulus.png"):
        assert want in text, f"{want!r} missing from the generated doc:\n{text}"
    assert list(d.glob("docs/.*.tmp")) == [], "temporary files left behind"


def test_report_png(written):
    d, _ = written
    png = (d / "docs/images/pareto_cumulus.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n", f"PNG signature {png[:8]!r}"
    w, h = struct.unpack(">II", png[16:24])
    assert (w, h) == (1200, 800) and len(png) > 10_000, f"{w}x{h}, {len(png)} bytes (want 1200x800, > 10 kB)"
    assert not (d / "docs/images/pareto_partial.png").exists(), "no plot for a scene without errors"


def test_report_splice_without_markers():
    def splice(text, body):
        return common.splice(text, report.START, report.END, body, new_doc=report.NEW_DOC)

    block = splice("Hand only.\n", "GEN")
    assert block == "Hand only.\n\n<!-- generated:start -->\nGEN\n<!-- generated:end -->\n", repr(block)
    again = splice(block, "NEW")
    assert again == block.replace("GEN", "NEW"), f"re-generation must only change the block: {again!r}"
    assert splice("", "GEN").startswith("# "), "a new doc gets a title"


def test_write_exr_round_trips_through_load_exr(tmp_path):
    """The sweep's averaged reference is written with write_exr (uncompressed float
    scanlines) and read back with load_exr: exact, tolerance 0."""
    rgb = np.random.default_rng(3).uniform(0.0, 4.0, (5, 7, 3)).astype(np.float32)
    path = tmp_path / "ref.exr"
    metrics.write_exr(path, rgb)
    back = metrics.load_exr(path)
    assert back.shape == (5, 7, 3) and np.array_equal(back, rgb), (back.shape, float(np.abs(back - rgb).max()))
    metrics.write_png(tmp_path / "ref.png", rgb, scale=2)
    assert (tmp_path / "ref.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
