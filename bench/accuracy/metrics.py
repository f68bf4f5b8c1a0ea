"""Error measures for the accuracy bench (issue 6): density-field error, image
error against a reference render (RMSE in linear radiance, mean FLIP), the
noise floor of a reference made from two seeds, and an EXR loader.

Units
-----
* Field errors are *relative*: absolute density differences divided by the
  exact field's range (max - min) over the same sample points, so 0.01 means
  "1 % of the density range".
* Image RMSE is in linear scene radiance (the values Cycles writes to a float
  EXR, no view transform), over the R, G, B channels; alpha is ignored.
* FLIP is NVIDIA's perceptual difference (0 = identical, 1 = maximal), the mean
  over pixels, computed by flip_evaluator in LDR mode (see image_flip).

Only numpy is needed, plus flip_evaluator for FLIP / EXR loading and bpy as a
fallback EXR loader (both imported lazily).
"""
import os
import struct

import numpy as np
from common import atomic_write

__all__ = ["field_error", "image_rmse", "image_flip", "load_exr", "noise_floor", "srgb_encode"]


def _array(name, value):
    """`value` as a float64 array; ValueError naming `name` if it is empty or not finite."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not a numeric array ({e})") from None
    if a.size == 0:
        raise ValueError(f"{name}: empty array")
    bad = ~np.isfinite(a)
    if bad.any():
        first = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{name}: {int(bad.sum())} non-finite value(s), first at index {first} = {a[first]}")
    return a


def field_error(approx, exact):
    """Relative error of a density field sampled at the same points.

    approx, exact: arrays of equal shape (any shape), finite values.
    Returns dict(rms=, max=, range=):
      rms   = sqrt(mean((approx - exact)^2)) / R
      max   = max(|approx - exact|) / R
      range = exact.max() - exact.min()  (the raw range, in density units)
    where R = range, or R = 1 when range == 0 (a constant exact field: the errors
    are then absolute density differences, never NaN / inf).
    Raises ValueError naming the argument on a shape mismatch, empty or
    non-finite input.
    """
    a = _array("approx", approx)
    e = _array("exact", exact)
    if a.shape != e.shape:
        raise ValueError(f"approx has shape {a.shape} but exact has shape {e.shape}")
    rng = float(e.max() - e.min())
    scale = rng if rng > 0.0 else 1.0
    d = np.abs(a - e)
    return {"rms": float(np.sqrt(np.mean(d * d)) / scale), "max": float(d.max() / scale), "range": rng}


def _rgb_pair(test, ref):
    t = _array("test", test)
    r = _array("ref", ref)
    for name, a in (("test", t), ("ref", r)):
        if a.ndim != 3 or a.shape[2] not in (3, 4):
            raise ValueError(f"{name}: expected an HxWx3 or HxWx4 image, got shape {a.shape}")
    if t.shape[:2] != r.shape[:2]:
        raise ValueError(f"test is {t.shape[1]}x{t.shape[0]} pixels but ref is {r.shape[1]}x{r.shape[0]}")
    return t[..., :3], r[..., :3]


def image_rmse(test, ref):
    """Root-mean-square difference in linear radiance over all pixels and the R,
    G, B channels (alpha, if present, is ignored): sqrt(mean((test - ref)^2)).
    test, ref: HxWx3 or HxWx4 float arrays of the same width and height."""
    t, r = _rgb_pair(test, ref)
    return float(np.sqrt(np.mean((t - r) ** 2)))


def srgb_encode(linear):
    """Linear radiance -> display-referred sRGB values in [0, 1]: clip to [0, 1],
    then the sRGB transfer function (IEC 61966-2-1: 12.92 x below 0.0031308,
    1.055 x^(1/2.4) - 0.055 above)."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def image_flip(test, ref):
    """Mean FLIP error of `test` against the reference `ref` (a float in [0, 1]).

    Both inputs are linear radiance (HxWx3/4, alpha ignored). They are turned
    into LDR images the way a viewer shows them without a view transform:
    clipped to [0, 1] and sRGB-encoded (srgb_encode). flip_evaluator's LDR mode
    expects exactly that: values in [0, 1], sRGB-encoded when inputsRGB=True
    (its documented default for LDR), which it linearises internally before
    converting to its opponent colour space. Viewing condition: FLIP's default
    67 pixels per degree.

    LDR rather than HDR-FLIP: it measures what the image looks like on screen
    with Blender's "Standard" view, and HDR-FLIP's automatic exposure range
    depends on the reference's brightest pixel (noisy in a path-traced render).
    Clipping means differences above 1.0 are invisible to this measure;
    image_rmse still sees them.

    LDR-FLIP is symmetric: both of its pipelines compare the two filtered
    images by distances (colour difference; difference of edge / point feature
    magnitudes), so image_flip(a, b) == image_flip(b, a) up to float rounding
    (tests/bench checks this to 1e-6). Only HDR-FLIP, whose exposure range is
    taken from the reference, is not. Pass the reference second anyway.
    """
    import flip_evaluator

    t, r = _rgb_pair(test, ref)
    t8 = np.ascontiguousarray(srgb_encode(t), dtype=np.float32)
    r8 = np.ascontiguousarray(srgb_encode(r), dtype=np.float32)
    _, mean, _ = flip_evaluator.evaluate(r8, t8, "LDR", inputsRGB=True, applyMagma=False,
                                         computeMeanError=True, parameters={})
    return float(mean)


def noise_floor(ref_a, ref_b):
    """The noise of the reference, from two reference renders that differ only in
    the seed (ref_a, ref_b: HxWx3/4 linear radiance).

    Returns dict(
      noise_rmse=image_rmse(ref_a, ref_b),   # difference of the two seed renders
      noise_flip=image_flip(ref_a, ref_b),   # the same in FLIP (ref_b as reference)
      reference_rmse=noise_rmse / 2)         # estimated RMSE of the reference vs truth

    Why / 2: with a = T + e_a and b = T + e_b, where e_a and e_b are independent
    zero-mean noise of per-pixel standard deviation s, rmse(a, b) ~ sqrt(2) s.
    The reference is the average (a + b) / 2 = T + (e_a + e_b) / 2, whose noise
    has standard deviation s / sqrt(2) = rmse(a, b) / 2. Errors measured against
    the reference below that value are not resolved. FLIP is not linear in the
    noise, so no such scaling is given for it: noise_flip is the FLIP distance
    between two equally good renders, an upper bound of what FLIP can resolve.
    """
    rmse = image_rmse(ref_a, ref_b)
    return {"noise_rmse": rmse, "noise_flip": image_flip(ref_a, ref_b), "reference_rmse": rmse / 2.0}


# ------------------------------------------------------------------ EXR --

# OpenEXR compression codes (header attribute "compression") that the tinyexr
# inside flip_evaluator decodes; verified on Blender-written files: NONE, RLE,
# ZIPS, ZIP and PIZ load, PXR24 / B44 / DWAA / DWAB do not.
_EXR_CODECS = ("NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB", "HTJ2K")
_TINYEXR_CODECS = {"NONE", "RLE", "ZIPS", "ZIP", "PIZ"}


def exr_header(path):
    """The few header facts load_exr needs: dict(compression=str, channels=[names],
    tiled=bool, multipart=bool, deep=bool). ValueError if `path` is not OpenEXR."""
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file (magic {data[:4]!r})")
    flags = struct.unpack_from("<I", data, 4)[0]
    info = {"compression": None, "channels": [], "tiled": bool(flags & 0x200),
            "multipart": bool(flags & 0x1000), "deep": bool(flags & 0x800)}
    pos = 8
    try:
        while data[pos] != 0:  # attributes of the first part, until the empty name
            end = data.index(b"\0", pos)
            name = data[pos:end].decode("latin-1")
            tend = data.index(b"\0", end + 1)
            kind = data[end + 1:tend].decode("latin-1")
            size = struct.unpack_from("<i", data, tend + 1)[0]
            value = data[tend + 5:tend + 5 + size]
            if name == "compression" and kind == "compression":
                code = value[0]
                info["compression"] = _EXR_CODECS[code] if code < len(_EXR_CODECS) else f"code {code}"
            elif name == "channels" and kind == "chlist":
                p = 0
                while p < len(value) and value[p] != 0:
                    e = value.index(b"\0", p)
                    info["channels"].append(value[p:e].decode("latin-1"))
                    p = e + 1 + 16  # pixel type, pLinear + reserved, xSampling, ySampling
            pos = tend + 5 + size
    except (IndexError, ValueError, struct.error):
        raise ValueError(f"{path}: truncated or malformed OpenEXR header") from None
    return info


def load_exr(path):
    """A float EXR's linear RGB as a float32 HxWx3 array (row 0 = top of the image).

    Fast path: flip_evaluator's built-in loader (tinyexr, no colour transform),
    used when the header says single-part scanline RGB(A) with a codec it
    decodes (NONE, RLE, ZIPS, ZIP, PIZ) — Blender's defaults. Its loader calls
    exit() on a file it cannot read, so the header is checked here first.
    Otherwise (DWAA/DWAB/PXR24/B44, tiled, multilayer, deep): Blender's image loader via
    bpy, imported lazily (slow the first time, ~1 s), with the colour space set
    to Non-Color so the stored values come back untouched, rows flipped to
    top-first. OpenEXR / OpenImageIO / imageio are not available in the venv.
    """
    path = os.fspath(path)
    info = exr_header(path)  # FileNotFoundError / ValueError before any exit()
    names = info["channels"]
    if (info["compression"] in _TINYEXR_CODECS and not (info["multipart"] or info["deep"] or info["tiled"])
            and {"R", "G", "B"} <= set(names)):
        import flip_evaluator

        img = np.asarray(flip_evaluator.load(path), dtype=np.float32)
        if img.ndim == 3 and img.shape[2] >= 3:
            return np.ascontiguousarray(img[..., :3])
    return _load_exr_bpy(path)


def _load_exr_bpy(path):
    import bpy

    img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    try:
        img.colorspace_settings.name = "Non-Color"
        w, h = img.size
        ch = img.channels
        if w == 0 or h == 0:
            raise ValueError(f"{path}: Blender could not read the image")
        px = np.empty(w * h * ch, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    px = px.reshape(h, w, ch)[::-1]
    if ch < 3:
        px = np.repeat(px[..., :1], 3, axis=2)
    return np.ascontiguousarray(px[..., :3])


def write_exr(path, rgb):
    """An uncompressed scanline float RGB OpenEXR file (for the averaged reference)."""
    rgb = np.asarray(rgb, np.float32)
    h, w, _ = rgb.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<I", 2)
              + attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    line = 8 + 3 * 4 * w
    start = len(header) + 8 * h
    offsets = struct.pack(f"<{h}Q", *[start + y * line for y in range(h)])
    body = b"".join(struct.pack("<ii", y, 3 * 4 * w)
                    + b"".join(rgb[y, :, c].astype("<f4").tobytes() for c in (2, 1, 0)) for y in range(h))
    atomic_write(path, header + offsets + body)


def write_png(path, rgb, scale=3):
    from PIL import Image
    img = Image.fromarray((srgb_encode(rgb) * 255 + 0.5).astype(np.uint8))
    img = img.resize((img.width * scale, img.height * scale), Image.NEAREST)
    img.save(path)
