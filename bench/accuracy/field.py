"""Field errors of the accuracy sweep (cloudgen_native, no Blender).

- bake_field_error: a baked grid against the exact field at N random points in
  the box. The bake's value at a point is the trilinear interpolation of the
  grid's voxel-centre values (`cloudgen bake` layout: voxel = longest side /
  resolution, n = ceil(box / voxel) per axis, origin = -n·voxel/2, centre of
  voxel i at origin + (i + ½)·voxel; outside the grid the background 0). Only
  the 8 voxel centres around each point are evaluated, never the grid. With
  LOD the centres take cloudgen_native.density(..., footprint=voxel) when the
  module has it (else all octaves, and the result says "lod": "ignored");
  values <= tolerance become 0; --half rounds through float16.
- detail_field_error: the field with another noise_detail against the preset's.
- preview_error: cloudgen_native.slice at N pixels across, upsampled bilinearly
  to the 1024-pixel slice and compared with it.
Errors: RMS and max of |approx - exact| over the points divided by the exact
field's range (max - min) over the same points (metrics.field_error).
"""
from __future__ import annotations

import time

import numpy as np

from accuracy import metrics

N_POINTS = 20000
SEED = 20261122


def _field_error(approx, exact):
    """(rms, max, range) of metrics.field_error."""
    res = metrics.field_error(approx, exact)
    return float(res["rms"]), float(res["max"]), float(res["range"])


def values(params):
    import cloudgen_native as cn
    return cn.resolve_params(dict(params))


def sample_points(box, n=N_POINTS, seed=SEED):
    rng = np.random.default_rng(seed)
    return (rng.random((n, 3)) - 0.5) * np.asarray(box, np.float64)


def has_footprint():
    import cloudgen_native as cn
    try:
        cn.density(cn.defaults(), [[0.0, 0.0, 0.0]], footprint=0.1)
        return True
    except TypeError:
        return False


def density(params, points, footprint=None):
    """(values, lod_applied)."""
    import cloudgen_native as cn
    pts = np.ascontiguousarray(points, np.float64)
    if footprint is not None and has_footprint():
        return np.asarray(cn.density(params, pts, footprint=float(footprint)), np.float64), True
    return np.asarray(cn.density(params, pts), np.float64), footprint is None


def grid_layout(box, resolution=None, voxel=None):
    box = np.asarray(box, np.float64)
    if voxel is None:
        voxel = float(box.max()) / resolution
    n = np.ceil(box / voxel - 1e-9).astype(np.int64)
    origin = -n * voxel / 2.0
    return voxel, n, origin


def baked_at(params, points, voxel, n, origin, lod=True, tolerance=0.0, half=False):
    """Trilinear interpolation of the voxel-centre values around each point."""
    u = (points - origin) / voxel - 0.5
    i0 = np.floor(u).astype(np.int64)
    f = u - i0
    corners = []
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                corners.append(i0 + np.array([dx, dy, dz]))
    idx = np.concatenate(corners)                        # (8N, 3)
    centres = origin + (idx + 0.5) * voxel
    vals, lod_applied = density(params, centres, footprint=voxel if lod else None)
    outside = np.any((idx < 0) | (idx >= n), axis=1)
    vals[outside] = 0.0                                  # background
    vals[vals <= tolerance] = 0.0
    if half:
        vals = vals.astype(np.float16).astype(np.float64)
    vals = vals.reshape(8, len(points))
    out = np.zeros(len(points))
    k = 0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                w = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
                     * (f[:, 2] if dz else 1 - f[:, 2]))
                out += w * vals[k]
                k += 1
    return out, lod_applied


def bake_field_error(params, resolution=None, lod=True, tolerance=0.0, half=False, voxel=None,
                     n_points=N_POINTS):
    v = values(params)
    pts = sample_points(v["box_size"], n_points)
    exact, _ = density(v, pts)
    vox, n, origin = grid_layout(v["box_size"], resolution, voxel)
    approx, lod_applied = baked_at(v, pts, vox, n, origin, lod, tolerance, half)
    rms, mx, rng = _field_error(approx, exact)
    return {"field_rms": rms, "field_max": mx, "field_range": rng, "field_points": len(pts), "voxel": vox,
            "grid": [int(x) for x in n],
            "field_lod": ("footprint" if lod_applied else "ignored") if lod else "off"}


def detail_field_error(params, detail, n_points=N_POINTS):
    v = values(params)
    pts = sample_points(v["box_size"], n_points)
    exact, _ = density(v, pts)
    approx, _ = density(dict(v, noise_detail=float(detail)), pts)
    rms, mx, rng = _field_error(approx, exact)
    return {"field_rms": rms, "field_max": mx, "field_range": rng, "field_points": len(pts)}


def preview_shape(box, axis, width):
    bx, by, bz = box
    across, up = {"x": (by, bz), "y": (bx, bz), "z": (bx, by)}[axis]
    height = int(round(width * up / max(across, 1e-9)))
    return width, max(8, min(4 * width, height))


def upsample_bilinear(img, height, width):
    """Pixel-centre aligned bilinear resize (edges clamped)."""
    h, w = img.shape

    def coords(n_out, n_in):
        x = (np.arange(n_out) + 0.5) * n_in / n_out - 0.5
        x = np.clip(x, 0, n_in - 1)
        i0 = np.floor(x).astype(int)
        i1 = np.minimum(i0 + 1, n_in - 1)
        return i0, i1, x - i0

    r0, r1, fr = coords(height, h)
    c0, c1, fc = coords(width, w)
    top = img[r0][:, c0] * (1 - fc) + img[r0][:, c1] * fc
    bot = img[r1][:, c0] * (1 - fc) + img[r1][:, c1] * fc
    return top * (1 - fr[:, None]) + bot * fr[:, None]


def preview_error(params, size, exact_size=1024, axis="y", offset=0.5, runs=5):
    import cloudgen_native as cn
    v = values(params)
    w, h = preview_shape(v["box_size"], axis, size)
    W, H = preview_shape(v["box_size"], axis, exact_size)
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        img = np.asarray(cn.slice(v, axis, offset, w, h), np.float64)
        times.append(time.perf_counter() - t0)
    exact = np.asarray(cn.slice(v, axis, offset, W, H), np.float64)
    approx = upsample_bilinear(img, H, W) if (h, w) != (H, W) else img
    rms, mx, rng = _field_error(approx.ravel(), exact.ravel())
    return {"field_rms": rms, "field_max": mx, "field_range": rng, "slice_s": min(times), "slice_s_all": times,
            "slice_size": [w, h], "exact_size": [W, H], "axis": axis, "offset": offset}
