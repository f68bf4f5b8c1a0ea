"""Where a point bake samples its voxels, and with what weight: the core's rule
(native/src/grid.cpp; docs/camera.md, "Box-filtered bakes") in numpy, for the add-on's own bake
(bake_local.py) and its 3D proxy (proxy_grid.py). No bpy here.

The grid of `cloudgen_native.bake_plan` may overhang the cloud's box by less than a voxel
on a side, and a layer thinner than a voxel (a cirrostratus at Draft) lies inside one cell.
The density is 0 outside the box, so a cell is sampled at its centre when it lies inside
the box; where it overhangs it (per axis), at the centre of its part inside the box, and
the value is weighted by that part's share of the cell. The cell's mean is kept: sampled at
its centre, a 0.5-unit veil in a 2.34-unit voxel became a whole voxel thick, its columns
summing to 5.6x the reference (now 1.19x; a cirrostratus at resolution 128, measured). The
rule is separable, so it is computed per axis: float32 throughout, in the core's order of
operations, so the values equal the CLI's bit for bit.
"""
from __future__ import annotations

import json

import numpy as np


def centre_axes(plan):
    """The voxel-centre coordinates along x, y and z (float32 arrays, as the core computes
    them: origin + (i + 1/2) * voxel)."""
    f = np.float32
    n, voxel, origin = plan["grid"], plan["voxel"], plan["origin"]
    return [f(origin[a]) + (np.arange(n[a], dtype=f) + f(0.5)) * f(voxel) for a in range(3)]


def sample_axes(plan):
    """(axes, shares): per axis, where each voxel is sampled and its part's share of the
    cell (1 inside the box), float32 arrays of the grid's length along that axis."""
    f = np.float32
    voxel = f(plan["voxel"])
    box = json.loads(plan["params_json"])["box_size"]
    axes, shares = [], []
    for a, centres in enumerate(centre_axes(plan)):
        half = f(0.5) * f(box[a])
        lo, hi = centres - f(0.5) * voxel, centres + f(0.5) * voxel
        clipped = (lo < -half) | (hi > half)
        inside_lo = np.maximum(lo, -half)
        span = np.maximum(np.minimum(hi, half) - inside_lo, f(0))
        axes.append(np.where(clipped, inside_lo + f(0.5) * span, centres).astype(f))
        shares.append(np.where(clipped, span / voxel, f(1)).astype(f))
    return axes, shares


def share_block(shares, k0=0, k1=None):
    """The weights of the voxels [:, :, k0:k1] as an (nx, ny, k1 - k0) float32 array: the
    product of the axes' shares, x first (the core's order)."""
    xy = shares[0][:, None] * shares[1][None, :]
    return (xy[:, :, None] * shares[2][None, None, k0:k1]).astype(np.float32)
