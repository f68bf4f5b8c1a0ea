"""The accuracy sweep's configuration: one SweepConfig object, made once by
sweep.py's main and passed to every function that needs it (no module globals).
"""
from __future__ import annotations

import pathlib
import subprocess
from dataclasses import dataclass, field

from accuracy import scenes

ROOT = pathlib.Path(__file__).resolve().parents[2]
PY45 = ROOT / ".venv/bin/python"
PY50 = ROOT / ".venv-blender5/bin/python"
CLOUDGEN = ROOT / "build/bin/cloudgen"
RENDER_JOB = pathlib.Path(__file__).resolve().parent / "render_job.py"
BAKE_RUNS = 3
VDB_MATERIAL = 2  # render_cloud.py --vdb shader version (1 squared the density): part of the cache key


@dataclass
class SweepConfig:
    """What one run of the sweep measures and where it writes.

    out: the results folder (accuracy.json, accuracy_cache/, images/);
    quick: the smoke-test sizes (scenes.QUICK_*), two settings per knob;
    runs: renders per point (best of); bake_runs: bakes per point (best of);
    machine: common.machine_info() at the start of the run;
    versions: Blender version strings seen, by "4.5" / "5.0" (filled while measuring)."""

    out: pathlib.Path
    quick: bool = False
    runs: int = 2
    bake_runs: int = BAKE_RUNS
    machine: dict = field(default_factory=dict)
    versions: dict = field(default_factory=dict)
    cloudgen: pathlib.Path = CLOUDGEN
    _tiers: dict | None = field(default=None, repr=False)
    _cli_help: str | None = field(default=None, repr=False)

    @property
    def size(self):
        return scenes.QUICK_IMAGE_SIZE if self.quick else scenes.IMAGE_SIZE

    @property
    def base(self):
        """The render settings of every swept point unless its knob changes them."""
        return scenes.QUICK_BASE if self.quick else scenes.BASE

    def reference_settings(self, scene, blender="4.5"):
        if blender == "4.5":
            return scenes.QUICK_REFERENCE if self.quick else scenes.REFERENCE[scene]
        return scenes.QUICK_REFERENCE_50 if self.quick else scenes.REFERENCE_50[scene]

    @property
    def cache(self):
        return self.out / "accuracy_cache"

    @property
    def images(self):
        return self.out / "images"

    @property
    def results(self):
        return self.out / "accuracy.json"

    def tiers(self) -> dict:
        """The quality tiers (cloudgen_native.tiers()), read once."""
        if self._tiers is None:
            import cloudgen_native as cn
            self._tiers = cn.tiers()
        return self._tiers

    def cli_help(self) -> str:
        """`cloudgen bake --help` (which options the CLI has), asked once."""
        if self._cli_help is None:
            try:
                self._cli_help = subprocess.run([str(self.cloudgen), "bake", "--help"], capture_output=True,
                                                text=True).stdout
            except OSError:
                self._cli_help = ""
        return self._cli_help
