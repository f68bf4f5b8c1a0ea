"""The gallery's camera finish (scripts/camera_finish.py; numpy and Pillow, no Blender): the
grain it adds is the stated amount, it leaves the picture's levels where they were, the
vignette falls to the stated corner, it is repeatable, and its file is written atomically."""
import sys

import numpy as np
import pytest
from test_cli import REPO_ROOT

sys.path.insert(0, str(REPO_ROOT / "scripts"))
import camera_finish as cf  # noqa: E402


def _flat(level, h=120, w=200):
    return np.full((h, w, 3), level, np.uint8)


@pytest.mark.parametrize("level", [40, 118, 200])
def test_grain_is_a_few_levels_and_keeps_the_mean(level):
    """Centre of a flat picture (vignette < 1 % there): mean within 1 level, grain std 0.8-4
    display levels (shot noise: more in the mid-tones than near black)."""
    out = cf.finish(_flat(level), seed=5).astype(np.float64)
    centre = out[50:70, 85:115]
    lin_v = 1.0 - (1.0 - cf.VIGNETTE_CORNER) * 0.025  # r^2 <= 0.025 in this window (0.024)
    expect = 255.0 * cf.srgb_encode(cf.vignette(cf.srgb_to_linear(level / 255.0), lin_v))
    assert abs(centre.mean() - level) < 1.0 + abs(level - expect), f"level {level}: mean {centre.mean():.2f}"
    assert 0.8 < centre.std() < 4.0, f"level {level}: grain std {centre.std():.2f} levels"


@pytest.mark.parametrize("level", [60, 180])
def test_vignette_reaches_the_corner_value(level):
    """A corner's light is the centre's with the scene light scaled by VIGNETTE_CORNER behind
    the shoulder (cf.vignette), within 3 % (grain averaged out); in the shadows (level 60,
    display light 0.045) that is VIGNETTE_CORNER itself within 3 %."""
    out = cf.finish(_flat(level, 240, 400), seed=1).astype(np.float64) / 255.0
    lin = cf.srgb_to_linear(out)
    ratio = lin[:6, :6].mean() / lin[115:125, 195:205].mean()
    flat = cf.srgb_to_linear(level / 255.0)
    expect = cf.vignette(flat, cf.VIGNETTE_CORNER) / flat
    assert abs(ratio - expect) < 0.03, f"level {level}: corner/centre {ratio:.3f}, expected {expect:.3f}"
    if level == 60:
        assert abs(ratio - cf.VIGNETTE_CORNER) < 0.03, f"corner/centre {ratio:.3f} in the shadows"


def test_vignette_keeps_white_and_order():
    """The shoulder: 1 stays 1, 0 stays 0, brighter stays brighter (1e-12), and a clipped
    render pixel (255) is 255 in every corner of the finished picture (blind round 24: "no
    pixel at pure white even with the sun in frame")."""
    v = np.linspace(0.0, 1.0, 2001)
    for f in (0.5, cf.VIGNETTE_CORNER, 1.0):
        out = cf.vignette(v, f)
        assert abs(out[-1] - 1.0) < 1e-12 and abs(out[0]) < 1e-12, f"falloff {f}: ends {out[0]}, {out[-1]}"
        assert np.all(np.diff(out) > 0.0), f"falloff {f}: not increasing"
        assert np.all(out <= v + 1e-12), f"falloff {f}: brightened"
    out = cf.finish(_flat(255, 240, 400), seed=3)
    assert out.min() == 255, f"a clipped white picture came out with {out.min()} somewhere"


def test_jpeg_has_no_block_grid(tmp_path):
    """A smooth sky gradient with its grain, finished to JPEG: the mean step across 8-pixel
    block edges is at most 1.15 times the step inside blocks (1.10 here; the PNG: 1.00 +- 0.05; quality
    95 4:2:0 gave 1.36 here and 1.25 on the gallery, a visible grid)."""
    from PIL import Image

    h, w = 180, 320
    yy = np.linspace(0.0, 1.0, h)[:, None]
    sky = np.stack([90 + 60 * yy, 140 + 50 * yy, 200 + 30 * yy], axis=-1) * np.ones((1, w, 1))
    src, dst = str(tmp_path / "sky.png"), str(tmp_path / "sky.jpg")
    Image.fromarray((sky + 0.5).astype(np.uint8)).save(src)
    cf.finish_file(src, dst, seed=7, iso=100)
    with Image.open(dst) as im:
        a = np.asarray(im.convert("RGB")).astype(np.float64).mean(axis=2)
    ratios = []
    for d in (np.abs(np.diff(a, axis=1)), np.abs(np.diff(a, axis=0)).T):
        edge = d[:, 7::8].mean()
        inside = np.delete(d, np.s_[7::8], axis=1).mean()
        ratios.append(edge / inside)
    assert max(ratios) < 1.15, f"block edge / inside step {ratios} at quality {cf.JPEG_QUALITY}"


def test_srgb_decode_inverts_the_encode():
    """srgb_to_linear is the inverse of bench's srgb_encode over [0, 1] (1e-12), both pieces."""
    v = np.linspace(0.0, 1.0, 1001)
    assert np.max(np.abs(cf.srgb_encode(cf.srgb_to_linear(v)) - v)) < 1e-12


def test_repeatable_per_seed_and_different_between_seeds():
    rng = np.random.default_rng(0)
    img = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    a, b, c = cf.finish(img, 3), cf.finish(img, 3), cf.finish(img, 4)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_sharpening_overshoots_an_edge_and_clips_without_wrapping():
    """A step 60 -> 190 gets an in-camera halo: a dark undershoot and a bright overshoot of at
    least 3 levels (averaged over the rows). A step 0 -> 255, whose halo would leave [0, 255],
    is clipped, not wrapped round (a wrapped pixel would sit near the other end of the range):
    next to the edge the dark side averages at most 3 levels with no pixel above 30 (read noise
    on black reaches about 13), the bright side averages at least 252 with none below 200."""
    img = _flat(60)
    img[:, 100:] = 190
    out = cf.finish(img, seed=2).astype(np.float64)[40:80].mean(axis=0).mean(axis=1)
    assert out[98:100].min() < out[80:90].mean() - 3, out[94:106]
    assert out[100:102].max() > out[110:120].mean() + 3, out[94:106]
    img = _flat(0)
    img[:, 100:] = 255
    out = cf.finish(img, seed=2)[40:80].astype(np.float64)
    dark, bright = out[:, 90:100], out[:, 100:110]
    assert dark.mean() <= 3 and dark.max() <= 30, (dark.mean(), dark.max())
    assert bright.mean() >= 252 and bright.min() >= 200, (bright.mean(), bright.min())


def test_rejects_what_is_not_an_rgb8_picture():
    with pytest.raises(ValueError, match="h x w x 3 uint8"):
        cf.finish(np.zeros((4, 4), np.uint8), 0)
    with pytest.raises(ValueError, match="h x w x 3 uint8"):
        cf.finish(np.zeros((4, 4, 3), np.float32), 0)


def test_finish_file_writes_a_jpeg_and_no_partial_file(tmp_path):
    from PIL import Image

    src = tmp_path / "in.png"
    Image.fromarray(_flat(118)).save(src)
    dst = tmp_path / "out.jpg"
    cf.finish_file(str(src), str(dst), seed=0)
    with Image.open(dst) as im:
        assert im.format == "JPEG" and im.size == (200, 120)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.png", "out.jpg"]


def test_finish_file_failing_mid_write_keeps_the_old_file(tmp_path, monkeypatch):
    """A write that fails after the new JPEG's bytes went to disk, before it took the old
    file's place (here: the rename raises), leaves the JPEG that was there untouched and no
    partial file beside it."""
    import os

    from PIL import Image

    src = tmp_path / "in.png"
    Image.fromarray(_flat(118)).save(src)
    dst = tmp_path / "out.jpg"
    dst.write_bytes(b"the old picture")

    def failing_replace(a, b):
        assert os.path.getsize(a) > 100, "the new JPEG was written before the rename"
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(OSError, match="disk full"):
        cf.finish_file(str(src), str(dst), seed=0)
    assert dst.read_bytes() == b"the old picture"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.png", "out.jpg"]


def test_command_line_seeds_each_file_by_its_name(tmp_path):
    """Two pictures with the same pixels but different names get different grain (no fixed
    pattern repeated over a gallery); the same name gives the same file."""
    from PIL import Image

    for name in ("a.png", "b.png"):
        Image.fromarray(_flat(118)).save(tmp_path / name)
    cf.main([str(tmp_path / "a.png"), str(tmp_path / "a.jpg")])
    cf.main([str(tmp_path / "b.png"), str(tmp_path / "b.jpg")])
    cf.main([str(tmp_path / "a.png"), str(tmp_path / "a2.jpg")])
    assert (tmp_path / "a.jpg").read_bytes() == (tmp_path / "a2.jpg").read_bytes()
    assert (tmp_path / "a.jpg").read_bytes() != (tmp_path / "b.jpg").read_bytes()


@pytest.mark.parametrize("iso", [100.0, 800.0, 3200.0])
def test_grain_grows_with_the_iso(iso):
    """Mid-grey's grain at `iso` against ISO 200, within 10 %: the gain g = iso / 200 scales the
    shot variance by g and the read deviation by g, so the deviation by
    sqrt((g SHOT L + g^2 READ^2) / (SHOT L + READ^2)) (from 0.70 at ISO 100 to 4.6 at 3200)."""
    base = cf.finish(_flat(118), seed=9).astype(np.float64)[40:80, 70:130].std()
    got = cf.finish(_flat(118), seed=9, iso=iso).astype(np.float64)[40:80, 70:130].std()
    g, lin = iso / cf.BASE_ISO, cf.srgb_to_linear(118 / 255.0)
    expect = base * ((g * cf.SHOT * lin + (g * cf.READ) ** 2) / (cf.SHOT * lin + cf.READ ** 2)) ** 0.5
    assert abs(got / expect - 1.0) < 0.10, f"iso {iso}: std {got:.2f} levels, expected {expect:.2f}"


def test_auto_iso_follows_the_light():
    """Full sun gives SUNNY_ISO, and so does light PROGRAM_STOPS below it (aperture and shutter);
    eight times less light than that, eight times the ISO; clamped to ISO_RANGE however dark or
    bright (no overflow for extreme ratios); no light, or non-finite, is refused."""
    program = 2.0 ** cf.PROGRAM_STOPS
    assert cf.iso_for_light(0.5, 0.5) == cf.SUNNY_ISO
    assert cf.iso_for_light(0.5 / program, 0.5) == pytest.approx(cf.SUNNY_ISO)
    assert cf.iso_for_light(0.5 / (8 * program), 0.5) == pytest.approx(8 * cf.SUNNY_ISO)
    assert cf.iso_for_light(1e-300, 0.5) == cf.ISO_RANGE[1]
    assert cf.iso_for_light(1e300, 0.5) == cf.ISO_RANGE[0]
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="finite and > 0"):
            cf.iso_for_light(bad, 0.5)


@pytest.mark.parametrize("iso", [50.0, 6400.0, float("nan"), "400"])
def test_rejects_an_iso_out_of_range_and_names_it(iso, tmp_path):
    with pytest.raises(ValueError, match=r"iso must be a number in \[100, 3200\]"):
        cf.finish(_flat(118), seed=0, iso=iso)
    with pytest.raises(ValueError, match="iso must be"):
        cf.finish_file(str(tmp_path / "missing.png"), str(tmp_path / "out.jpg"), iso=iso)
    assert not (tmp_path / "out.jpg").exists()


def test_colour_noise_is_a_small_part_of_the_grain():
    """At ISO 1600 on mid-grey (grain well above the 8-bit step), the colour noise std(R - G)
    against the luminance grain std((R + G + B) / 3) is c sqrt(2) / sqrt(1 - c^2 + c^2 / 3)
    for c = CHROMA_SHARE (0.29 at 0.2), within 15 %."""
    out = cf.finish(_flat(118), seed=4, iso=1600.0).astype(np.float64)[30:90, 50:150]
    colour = (out[..., 0] - out[..., 1]).std()
    grain = out.mean(axis=2).std()
    c = cf.CHROMA_SHARE
    expect = c * 2 ** 0.5 / (1.0 - c * c + c * c / 3.0) ** 0.5
    assert abs(colour / grain / expect - 1.0) < 0.15, f"colour/grain {colour / grain:.3f}, expected {expect:.3f}"
