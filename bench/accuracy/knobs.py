"""The knobs of the accuracy sweep: one Knob row each, carrying its settings and
its own point factory.

A point is a dict: knob, setting, label, blender ("4.5" / "5.0"), render (the
render job's specification, or None), bake (the `cloudgen bake` specification,
or None), field (what field error to compute, or None), and for the tier knob a
variant ("vdb" / "procedural"). measure.py measures it; the specifications are
its cache key.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from accuracy import scenes
from accuracy.config import PY50, VDB_MATERIAL, SweepConfig

TOLERANCE_AT = 128  # the tolerance knob's bake resolution (--quick: QUICK_AT)
QUICK_AT = 64
PRESET = "preset"  # a noise_detail setting: the preset's own value


@dataclass(frozen=True)
class Knob:
    """name: as in the results; title: the report's heading; settings / quick: the settings swept (text), in a full
    run and with --quick, or a function of the configuration (the tiers);
    make_point(knob, setting, cfg) -> [point, ...]; scenes: the scenes it runs on
    (None: all); extra_settings: more settings on some scenes (full runs only);
    available(cfg): whether this build / machine can measure it."""

    name: str
    title: str
    settings: tuple | Callable[[SweepConfig], list]
    quick: tuple
    make_point: Callable[[Knob, str, SweepConfig], list]
    scenes: tuple | None = None
    extra_settings: dict = field(default_factory=dict)
    available: Callable[[SweepConfig], bool] = lambda cfg: True

    def runs_on(self, scene: str) -> bool:
        only = scenes.SCENES[scene].get("knobs")
        return (self.scenes is None or scene in self.scenes) and (not only or self.name in only)

    def settings_for(self, scene: str, cfg: SweepConfig, preset_values: dict) -> list:
        """The settings to sweep on `scene` (PRESET resolved with the preset's values), without repeats."""
        chosen = self.quick if cfg.quick else self.settings
        chosen = list(chosen(cfg) if callable(chosen) else chosen)
        if not cfg.quick:
            chosen += self.extra_settings.get(scene, [])
        out = []
        for s in chosen:
            if s == PRESET:
                s = f"{preset_values['noise_detail']:g}"
            if s not in out:
                out.append(s)
        return out

    def points(self, setting: str, cfg: SweepConfig) -> list:
        return self.make_point(self, setting, cfg)


# ------------------------------------------------------------- point parts --


def bake_spec(resolution, half=False, lod=True, tolerance=0.0, skip=True, **extra):
    return dict({"resolution": int(resolution), "half": bool(half), "lod": bool(lod),
                 "tolerance": float(tolerance), "skip": bool(skip)}, **extra)


def base_render(cfg):
    """The procedural render every point starts from."""
    return {"source": "procedural", "samples": cfg.base["samples"], "step_rate": cfg.base["step_rate"],
            "seed": scenes.SWEEP_SEED, "size": list(cfg.size)}


def vdb_render(cfg, render=None):
    return dict(render or base_render(cfg), source="vdb", vdb_material=VDB_MATERIAL)


def point(knob, setting, cfg, label, **kw):
    return dict({"knob": knob.name, "setting": setting, "label": label, "blender": "4.5",
                 "render": base_render(cfg), "bake": None, "field": None}, **kw)


def baked(knob, setting, cfg, label, spec):
    """A uniform bake rendered with the VDB material; its field error from the same grid."""
    return [point(knob, setting, cfg, label, render=vdb_render(cfg), bake=spec, field={"kind": "bake", **spec})]


def mode_at(setting):
    """"on@128" -> ("on", "128")."""
    mode, res = setting.split("@")
    return mode, res


# ---------------------------------------------------------- point factories --


def procedural(k, s, cfg):
    return [point(k, s, cfg, f"Procedural OSL ({cfg.base['samples']} spp)")]


def bake_resolution(k, s, cfg):
    return baked(k, s, cfg, f"VDB {s}³", bake_spec(s))


def bake_half(k, s, cfg):
    return baked(k, s, cfg, f"VDB {s}³ half", bake_spec(s, half=True))


def lod(k, s, cfg):
    mode, res = mode_at(s)
    return baked(k, s, cfg, f"VDB {res}³ LOD {mode}", bake_spec(res, lod=mode == "on"))


def tolerance(k, s, cfg):
    res = QUICK_AT if cfg.quick else TOLERANCE_AT
    return baked(k, s, cfg, f"VDB {res}³ tolerance {s}", bake_spec(res, tolerance=float(s)))


def skip_empty(k, s, cfg):
    mode, res = mode_at(s)
    return baked(k, s, cfg, f"VDB {res}³ skip empty {mode}", bake_spec(res, skip=mode == "on"))


def noise_detail(k, s, cfg):
    return [point(k, s, cfg, f"Noise detail {s} (procedural)",
                  render=dict(base_render(cfg), params={"noise_detail": float(s)}),
                  field={"kind": "detail", "detail": float(s)})]


def step_rate(k, s, cfg):
    return [point(k, s, cfg, f"Step rate ×{s}", render=dict(base_render(cfg), step_rate=float(s)))]


def samples(k, s, cfg):
    return [point(k, s, cfg, f"{s} spp", render=dict(base_render(cfg), samples=int(s)))]


def volume_biased(k, s, cfg):
    render = dict(base_render(cfg), volume_biased="on" if s == "biased" else "off")
    return [point(k, s, cfg, f"Blender 5.0 {s}", blender="5.0", render=render)]


def preview_resolution(k, s, cfg):
    return [point(k, s, cfg, f"Preview {s} px", render=None,
                  field={"kind": "preview", "size": int(s), "exact_size": 1024})]


def tier(k, s, cfg):
    """Two points: the tier's bake rendered with its render settings, and those on the procedural material."""
    t = cfg.tiers()[s]
    tb, tr = t["bake"], t["render"]
    b = bake_spec(tb["resolution"], half=tb.get("half", False), lod=tb.get("lod", True),
                  tolerance=tb.get("tolerance", 0.0), quality=s)
    r = dict(base_render(cfg), samples=int(tr["samples"]), step_rate=float(tr["step_rate"]))
    name = t.get("label", s)
    return [point(k, s, cfg, f"{name} (VDB {tb['resolution']}³, {tr['samples']} spp)", render=vdb_render(cfg, r),
                  bake=b, field={"kind": "bake", **b}, variant="vdb"),
            point(k, s, cfg, f"{name} (procedural, {tr['samples']} spp)", render=r, variant="procedural")]


def camera_aware(k, s, cfg):
    """"ppv=2" or "ppv=1,margin=0": pixels per voxel and the margin around the view
    (default 0.5; margin=cli: the CLI's optical-depth default)."""
    kv = dict(item.split("=") for item in s.split(","))
    margin = 0.5 if "margin" not in kv else (None if kv["margin"] == "cli" else float(kv["margin"]))
    b = {"camera": True, "pixels_per_voxel": float(kv["ppv"]), "margin": margin, "lod": True, "half": False,
         "tolerance": 0.0, "skip": True}
    text = "default" if margin is None else f"{margin:g}"
    return [point(k, s, cfg, f"Camera-aware VDB, {kv['ppv']} px/voxel, margin {text}", render=vdb_render(cfg),
                  bake=b, field={"kind": "bake_camera"})]


# -------------------------------------------------------------------- rows --

KNOBS = (
    Knob("procedural", "Procedural (OSL at render time, no bake)",
         ("osl",), ("osl",), procedural),
    Knob("bake_resolution", "Bake resolution (uniform VDB)",
         ("64", "128", "256", "512"), ("32", "64"), bake_resolution),
    Knob("samples", "Samples per pixel",
         ("4", "16", "64", "256"), ("2", "8"), samples),
    Knob("step_rate", "Volume step rate",
         ("2", "1", "0.5", "0.25", "0.177"), ("2", "0.5"), step_rate),
    Knob("bake_half", "Half-float VDB",
         ("128", "256"), ("64",), bake_half),
    Knob("lod", "Level of detail (octaves capped at the voxel size)",
         ("on@128", "off@128", "on@256", "off@256"), ("on@64", "off@64"), lod),
    Knob("tolerance", "Bake tolerance",
         ("0", "0.01", "0.05", "0.1", "0.3", "1"), ("0", "0.1"), tolerance),
    Knob("skip_empty", "Skipping empty tiles",
         ("on@128", "off@128"), ("off@64",), skip_empty),
    Knob("noise_detail", "Noise detail (octaves)",
         ("1", "2", "3", "4", PRESET), ("2", PRESET), noise_detail),
    Knob("preview_resolution", "Preview slice resolution (field error only; time = slice time)",
         ("64", "128", "256", "512", "1024"), ("64", "256"), preview_resolution),
    Knob("tier", "Quality tiers (Draft / Preview / Final)",
         lambda cfg: list(cfg.tiers()), ("draft",), tier, available=lambda cfg: bool(cfg.tiers())),
    Knob("camera_aware", "Camera-aware bake",
         ("ppv=1", "ppv=2", "ppv=4"), ("ppv=2",), camera_aware,
         extra_settings={"cumulus_closeup": ("ppv=1,margin=0", "ppv=1,margin=cli")},  # where the margin can matter
         available=lambda cfg: "--camera" in cfg.cli_help()),
    Knob("volume_biased", "Biased volume rendering (Blender 5.0)",
         ("biased", "unbiased"), ("biased", "unbiased"), volume_biased, scenes=("cumulus",),
         available=lambda cfg: PY50.exists()),
)
BY_NAME = {k.name: k for k in KNOBS}
