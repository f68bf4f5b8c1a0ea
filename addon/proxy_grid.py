"""The 3D proxy's grid: the cloud's density sampled as a small point bake samples it,
written as a VDB that Blender's Volume object reads. No bpy here (the native and
OpenVDB modules are passed in), so it is tested and timed without Blender.

- grid: `cloudgen_native.bake_plan(params, resolution)` — the bake's own grid
  (docs/model.md §8: cubic voxels, `resolution` along the longest box side,
  centred, float32), so a proxy is exactly a low-resolution bake;
- values: `cloudgen_native.density(params, points, footprint=voxel)`, i.e. with
  the bake's level of detail (octaves finer than a voxel replaced by their mean:
  a 64-voxel proxy would alias them anyway), at the voxel centres; where a cell
  overhangs the cloud's box, at the centre of its part inside the box, times that
  part's share of the cell (the bake's rule, grid_points.py: a veil thinner than a
  voxel keeps its column instead of becoming a voxel thick);
- file: one float grid `density` (fog volume, background 0, zero voxels inactive,
  index -> local transform of the bake), full floats, written to a temporary file
  in the same folder and renamed over the target (atomic: Blender never reads a
  half-written proxy). No metadata, no read-back: it is a throw-away viewport file.
"""
from __future__ import annotations

import os
import tempfile

import numpy as np

try:
    from . import grid_points
except ImportError:  # loaded by its path in tests, beside grid_points
    import grid_points

MIN_RESOLUTION = 32
MAX_RESOLUTION = 128
DEFAULT_RESOLUTION = 64


def check_resolution(resolution) -> int:
    r = int(resolution)
    if not MIN_RESOLUTION <= r <= MAX_RESOLUTION:
        raise ValueError(f"proxy resolution must be an integer in [{MIN_RESOLUTION}, {MAX_RESOLUTION}]; "
                         f"got {resolution}")
    return r


def compute(native, params, resolution):
    """(values, plan): the proxy grid's values, float32 of shape (nx, ny, nz), sampled as a
    point bake samples them (grid_points), and the core's bake plan (grid, voxel, origin).
    params: resolved."""
    plan = native.bake_plan(params, check_resolution(resolution), lod=True)
    axes, shares = grid_points.sample_axes(plan)
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    n = plan["grid"]
    values = np.asarray(native.density(params, points, 0, float(plan["voxel"])), dtype=np.float32)
    values = values.reshape(n[0], n[1], n[2]) * grid_points.share_block(shares)
    values[~(values > 0)] = 0  # background (and never NaN or negative in a grid)
    return values, plan


def _transform(vdb, plan):
    v = float(plan["voxel"])
    xform = vdb.createLinearTransform(voxelSize=v)
    translate = getattr(xform, "postTranslate", None) or xform.translate  # OpenVDB 12.x / 10.x bindings
    translate(tuple(float(plan["origin"][a]) + 0.5 * v for a in range(3)))
    return xform


def write(vdb, path, values, plan):
    """Write `values` as the grid `density` to path, atomically (temporary file beside it,
    then renamed). Raises OSError (or the OpenVDB module's error) and leaves no temporary
    file behind."""
    grid = vdb.FloatGrid()
    if values.any():
        grid.copyFromArray(values, ijk=(0, 0, 0), tolerance=0.0)
    grid.name = "density"
    try:
        grid.gridClass = vdb.GridClass.FOG_VOLUME
    except AttributeError:  # OpenVDB 10.x bindings
        grid.gridClass = "fog volume"
    grid.transform = _transform(vdb, plan)
    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    os.close(fd)
    try:
        vdb.write(tmp, grids=[grid])
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise
