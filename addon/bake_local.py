"""Bake to VDB inside Blender: densities from cloudgen_native, the grid written
through Blender's own OpenVDB Python module. No bpy here (the module objects are
passed in), so it runs in a worker thread and is tested without a window.

The file is the one `cloudgen bake` writes for the same parameters and settings
(docs/model.md §8, docs/addon.md "Bake inside Blender"):

- grid: cubic voxels, `resolution` along the longest box side,
  n_a = max(1, ceil(B_a / v - 1e-4)), origin = -n·v/2 (float32, as the core
  computes it); voxel (i,j,k) is sampled at origin + (i+½, j+½, k+½)·v with
  `cloudgen_native.density(params, points, footprint=v)` (footprint 0 with LOD
  off); a cell overhanging the box at the centre of its part inside it, weighted by
  that part's share of the cell (grid_points.py): the same kernel, points and weights
  as the CLI, so equal values voxel for voxel;
- one float grid `density`, class fog volume, background 0, voxels <= tolerance
  inactive, transform index -> local (scale v, translate origin + v/2), half
  floats when asked;
- metadata cloudgen_version, cloudgen_params (compact JSON, sorted keys),
  cloudgen_preset (when the parameters name one), cloudgen_time,
  cloudgen_resolution (the longest grid side), cloudgen_bake_key; the grid, the key,
  the parameter JSON and the LOD octaves all come from `cloudgen_native.bake_plan`
  (the core's own bake_grid / bake_key: nothing here recomputes them),
  cloudgen_lod_worley_octaves / cloudgen_lod_perlin_octaves.

A sequence (several files) works like `cloudgen bake --sequence --update`: a
file whose stored bake key equals the new one is kept, a file whose key equals
an earlier file's of this run is a byte copy of it, the rest is baked. Every
file appears atomically (a temporary file in the same folder, read back, then
renamed); a cancel or an error leaves no partial file (finished files stay).

    job = LocalBake(native, vdb, [(path, params, frame), ...], Settings(96))
    job.start(); ...; job.poll() -> None while running, else a BakeResult
"""
from __future__ import annotations

import os
import shutil
import struct
import tempfile
import threading
from dataclasses import dataclass

try:
    from . import grid_points
    from .bake_process import BAD_ARGUMENT, CANCELLED, IO_ERROR, OK, BakeResult
except ImportError:  # loaded by its path in tests (bake_process loaded first as a top-level module)
    import grid_points
    from bake_process import BAD_ARGUMENT, CANCELLED, IO_ERROR, OK, BakeResult

TILE = 8
MAX_POINTS_PER_CALL = 1 << 20   # one density() call: 12 MiB of points, a cancel check between calls


@dataclass
class Settings:
    resolution: int
    lod: bool = True
    tolerance: float = 0.0
    half: bool = False


class Cancelled(Exception):
    pass


def _f32(x):
    return struct.unpack("<f", struct.pack("<f", float(x)))[0]


def stored_key(native, vdb, path: str) -> str:
    """The cloudgen_bake_key of path's `density` grid ("" when missing or unreadable).
    The file is hostile until checked: cloudgen_native.check_vdb (header, descriptors,
    metadata; no OpenVDB) must pass before Blender's OpenVDB reads its metadata, so a
    damaged or crafted file costs "no key" (bake again), never Blender's process."""
    if not os.path.isfile(path) or native is None:
        return ""
    try:
        native.check_vdb(path)
    except ValueError:
        return ""
    try:
        for grid in vdb.readAllGridMetadata(path):  # grids without trees
            if grid.name == "density":
                return str(dict(grid.metadata).get("cloudgen_bake_key", ""))
    except Exception:  # noqa: BLE001 - any unreadable file is "no key"
        return ""
    return ""


def _temp_beside(path: str) -> str:
    """A temporary file next to `path`, with the mode a new file gets (0666 less the
    umask, as the CLI's files): mkstemp's 0600 would survive the rename and leave the
    bake unreadable to a farm that renders as another user."""
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp",
                               dir=os.path.dirname(path) or ".")
    umask = os.umask(0)
    os.umask(umask)
    os.fchmod(fd, 0o666 & ~umask)
    os.close(fd)
    return tmp


def _remove(path):
    try:
        os.remove(path)
    except OSError:
        pass


class LocalBake:
    """One bake run (a file or a sequence) in a worker thread; the BakeJob interface of
    bake_process (start, poll, wait, cancel, progress, on_progress)."""

    def __init__(self, native, vdb, entries, settings: Settings, update=False, on_progress=None,
                 threads=0, version=""):
        self.native, self.vdb = native, vdb
        self.entries = list(entries)          # (path, params (resolved), frame or None)
        self.settings = settings
        self.update = update
        self.on_progress = on_progress
        self.threads = threads
        self.version = version
        self._fraction = 0.0
        self._cancel = threading.Event()
        self._thread = None
        self._result = None
        self.active_voxels = []

    @property
    def progress(self) -> float:
        return 100.0 if self._result is not None and self._result.ok else 100.0 * self._fraction

    def start(self):
        self._thread = threading.Thread(target=self._run, name="cloudgen-bake", daemon=True)
        self._thread.start()
        return self

    def cancel(self):
        self._cancel.set()

    def poll(self):
        if self._thread is not None and self._thread.is_alive():
            return None
        return self._result

    def wait(self, timeout=None):
        self._thread.join(timeout)
        return self._result

    def run(self):
        """Synchronous: the BakeResult."""
        self._run()
        return self._result

    # -- the work ------------------------------------------------------------
    def _set_fraction(self, f):
        self._fraction = f
        if self.on_progress is not None:
            self.on_progress(100.0 * f)

    def _run(self):
        files = [e[0] for e in self.entries]
        frames = [e[2] for e in self.entries]
        result = BakeResult(OK, "", [], [], [], files, frames)
        try:
            done = {}  # bake key -> (path, frame) written or kept in this run
            n = len(self.entries)
            for index, (path, params, frame) in enumerate(self.entries):
                if self._cancel.is_set():
                    raise Cancelled()
                s = self.settings  # the grid, key and metadata come from the core, as the CLI's
                plan = self.native.bake_plan(params, s.resolution, lod=s.lod, half=s.half, tolerance=s.tolerance)
                key = plan["key"]
                if self.update and stored_key(self.native, self.vdb, path) == key:
                    result.kept.append(path)
                    done.setdefault(key, (path, frame))
                elif key in done:
                    self._copy(done[key][0], path)
                    result.copied.append((path, done[key][1]))
                else:
                    self._bake_one(path, params, plan, lambda f, i=index: self._set_fraction((i + f) / n))
                    result.paths.append(path)
                    done[key] = (path, frame)
                self._set_fraction((index + 1) / n)
            if result.copied or result.kept:
                result.message = f"{result.counts()} ({n} files)"
            else:
                result.message = f"baked {len(result.paths)} file(s): " + ", ".join(result.paths)
        except Cancelled:
            result.code = CANCELLED
            result.message = "bake cancelled; no partial file left" + (
                f" ({len(result.paths)} finished frame(s) kept)" if result.paths else "")
        except (ValueError, TypeError) as exc:
            result.code = BAD_ARGUMENT
            result.message = f"bad argument: {exc}"
        except MemoryError:
            result.code = IO_ERROR
            result.message = "out of memory: lower the resolution"
        except Exception as exc:  # noqa: BLE001 - OSError and the OpenVDB module's errors
            result.code = IO_ERROR
            result.message = f"I/O error: {exc}"
        self._result = result

    def _copy(self, source, path):
        tmp = _temp_beside(path)
        try:
            shutil.copyfile(source, tmp)
            if os.path.getsize(tmp) != os.path.getsize(source):
                raise OSError(f"copying {source} to {path} failed (disk full?)")
            os.replace(tmp, path)
        except BaseException:
            _remove(tmp)
            raise

    def _bake_one(self, path, params, plan, progress):
        import numpy as np  # noqa: PLC0415

        vdb, s = self.vdb, self.settings
        n, voxel = plan["grid"], plan["voxel"]
        f = np.float32
        footprint = float(voxel) if s.lod else 0.0
        grid = vdb.FloatGrid()
        axes, shares = grid_points.sample_axes(plan)
        layers = max(1, min(TILE, MAX_POINTS_PER_CALL // max(1, n[0] * n[1])))
        xy = np.stack([c.ravel() for c in np.meshgrid(axes[0], axes[1], indexing="ij")], axis=1)
        active = 0
        for k0 in range(0, n[2], layers):
            if self._cancel.is_set():
                raise Cancelled()
            k1 = min(k0 + layers, n[2])
            zs = axes[2][k0:k1]
            points = np.empty((xy.shape[0], zs.size, 3), dtype=f)
            points[:, :, 0:2] = xy[:, None, :]
            points[:, :, 2] = zs[None, :]
            values = np.asarray(self.native.density(params, points.reshape(-1, 3), self.threads, footprint),
                                dtype=f).reshape(n[0], n[1], k1 - k0)
            values *= grid_points.share_block(shares, k0, k1)
            values[~(values > f(s.tolerance))] = 0  # the CLI: d <= tolerance (and NaN) is background
            if values.any():
                active += int(np.count_nonzero(values))
                grid.copyFromArray(values, ijk=(0, 0, k0), tolerance=0.0)
            progress(k1 / n[2])
        self._write(path, grid, params, plan)
        self.active_voxels.append(active)

    def _write(self, path, grid, params, plan):
        vdb, s = self.vdb, self.settings
        n, voxel, origin, key = plan["grid"], plan["voxel"], plan["origin"], plan["key"]
        grid.name = "density"
        try:
            grid.gridClass = vdb.GridClass.FOG_VOLUME
        except AttributeError:
            grid.gridClass = "fog volume"
        v = float(voxel)
        xform = vdb.createLinearTransform(voxelSize=v)
        translate = getattr(xform, "postTranslate", None) or xform.translate  # 12.x / 10.x bindings
        translate(tuple(float(origin[a]) + 0.5 * v for a in range(3)))
        grid.transform = xform
        worley, perlin = plan["lod_octaves"]
        meta = {"cloudgen_version": self.version, "cloudgen_params": plan["params_json"],
                "cloudgen_time": _f32(params.get("time", 0.0)), "cloudgen_resolution": int(max(n)),
                "cloudgen_bake_key": key, "cloudgen_lod_worley_octaves": worley,
                "cloudgen_lod_perlin_octaves": perlin}
        if params.get("preset"):
            meta["cloudgen_preset"] = str(params["preset"])
        for k, value in meta.items():
            grid[k] = value
        grid.saveFloatAsHalf = bool(s.half)
        tmp = _temp_beside(path)
        try:
            vdb.write(tmp, grids=[grid])
            if self._cancel.is_set():
                raise Cancelled()
            # read back: the OpenVDB module does not report every failed write (a full disk)
            back = vdb.read(tmp, "density")
            if back.activeVoxelCount() != grid.activeVoxelCount() or back["cloudgen_bake_key"] != key:
                raise OSError(f"{path} was written but does not read back (disk full?)")
            os.replace(tmp, path)
        except BaseException:
            _remove(tmp)
            raise
