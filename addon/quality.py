"""Quality tiers: scene.cloudgen.quality (sidebar "Cloud Quality") and
bpy.ops.cloudgen.apply_quality(tier="draft").

The tiers (Draft, Preview, Final) come from the core, cloudgen_native.tiers()
(native/presets/tiers.json): label, description, render settings (Cycles
samples, scene volume step rate), bake settings (resolution, LOD, tolerance,
half floats), preview image size, and the benchmark's measured numbers, which
the enum's tooltips show ("not measured yet" when absent).

The enum's first item is "Custom": the settings as the user made them — nothing
is applied, and Bake to VDB uses its own values (resolution 96, full float,
LOD on). Choosing a tier applies it at once (same as the operator); a tier's
render settings changed by hand afterwards are listed in the panel ("changed
by hand") with a button to apply the tier again, and bakes keep using the
tier's bake settings. Without the core (or with one that has no tiers) the enum
offers only Custom and the panel says why.
"""
import bpy

from . import bridge
from .panel import SidebarPanel, tooltip, wrapped_label

CUSTOM = "CUSTOM"
PREVIEW_MIN, PREVIEW_MAX = 16, 512          # scene.cloudgen.preview_width limits
DEFAULT_BAKE = {"resolution": 96, "lod": True, "tolerance": 0.0, "half": False}  # Custom's

_items = []       # Blender needs dynamic enum strings kept alive
_applying = False


# ---------------------------------------------------------------- reading the tiers
def tiers() -> dict:
    """The core's tiers, or {} (tiers_error() says why)."""
    try:
        return bridge.tiers()
    except RuntimeError:
        return {}


def tiers_error():
    try:
        bridge.tiers()
    except RuntimeError as exc:
        return str(exc)
    return None


def _num(value, fmt):
    try:
        return format(float(value), fmt)
    except (TypeError, ValueError):
        return None


# How a tier's render looks next to the reference render (the benchmark's FLIP error,
# docs/accuracy.md), in words: (upper FLIP bound, words), first match.
LOOKS = ((0.03, "looks like the reference"), (0.06, "slight grain"),
         (0.10, "visible grain, softer detail"), (float("inf"), "rough: for blocking out"))


def look(flip) -> str:
    for bound, words in LOOKS:
        if float(flip) <= bound:
            return words
    return LOOKS[-1][1]


def measured_lines(tier: dict) -> list:
    """One line per measured scene, where, time and look: 'cumulus (128×96 px, 2026-11-22):
    render 3.2 s, bake 0.40 s, slight grain' (the look from the measured FLIP error, LOOKS)."""
    out = []
    for scene_name, m in (tier.get("measured") or {}).items():
        if not isinstance(m, dict):
            continue
        parts = []
        for key, label, fmt in (("render_s", "render", ".1f"), ("bake_s", "bake", ".2f")):
            text = _num(m.get(key), fmt) if key in m else None
            if text is not None and not (key == "bake_s" and float(m[key]) == 0.0):
                parts.append(f"{label} {text} s")
        if _num(m.get("flip"), "g") is not None:
            parts.append(look(m["flip"]))
        if parts:
            where = []
            if isinstance(m.get("image"), str):
                where.append(m["image"].replace("x", "×") + " px")
            if isinstance(m.get("measured_on"), str):
                where.append(m["measured_on"])
            head = f"{scene_name} ({', '.join(where)})" if where else scene_name
            out.append(f"{head}: " + ", ".join(parts))
    return out


def measured_text(tier: dict) -> str:
    lines = measured_lines(tier)
    return "; ".join(lines) if lines else "not measured yet"


def tier_label(name: str, tier: dict) -> str:
    return str(tier.get("label") or name.replace("_", " ").title())


def tier_tooltip(tier: dict) -> str:
    r, b = tier.get("render", {}), tier.get("bake", {})
    settings = []
    if "samples" in r:
        settings.append(f"{int(r['samples'])} samples")
    if "step_rate" in r:
        settings.append(f"step rate {float(r['step_rate']):g}")
    if "resolution" in b:
        settings.append(f"bake {int(b['resolution'])}³" + (" half" if b.get("half") else "")
                        + ("" if b.get("lod", True) else " full detail"))
    if "size" in tier.get("preview", {}):
        settings.append(f"preview {int(tier['preview']['size'])} px")
    desc = tooltip(tier.get("description", ""))
    head = (desc + ". ") if desc else ""
    return f"{head}{', '.join(settings)}. Measured: {measured_text(tier)}"


def tier_items(self, context):
    """Enum items: Custom, then the core's tiers in its order."""
    global _items
    items = [(CUSTOM, "Custom", "Your own render and bake settings: nothing is applied; "
              "Bake to VDB uses its own values (resolution 96)")]
    for name, tier in tiers().items():
        items.append((name, tier_label(name, tier), tier_tooltip(tier)))
    _items = items
    return _items


# ---------------------------------------------------------------- applying
def _scene_settings(scene):
    return getattr(scene, "cloudgen", None)


def apply(scene, name: str) -> dict:
    """Set the tier's render settings and preview size on scene and make it the scene's
    Cloud Quality (what bakes use). KeyError for an unknown tier. Returns the tier."""
    global _applying
    all_tiers = tiers()
    if name not in all_tiers:
        why = tiers_error()
        raise KeyError(f"unknown quality tier {name!r}; known: {', '.join(all_tiers) or 'none'}"
                       + (f" ({why})" if why else ""))
    tier = all_tiers[name]
    render = tier.get("render", {})
    c = scene.cycles
    if "samples" in render:
        c.samples = int(render["samples"])
    if "step_rate" in render and hasattr(c, "volume_step_rate"):  # Blender 5 has no step rate
        c.volume_step_rate = float(render["step_rate"])
    settings = _scene_settings(scene)
    if settings is not None:
        size = tier.get("preview", {}).get("size")
        if size is not None:
            settings.preview_width = max(PREVIEW_MIN, min(PREVIEW_MAX, int(size)))
        if settings.quality != name:
            _applying = True
            try:
                settings.quality = name
            finally:
                _applying = False
    return tier


def on_quality_changed(settings, context):
    """Update of scene.cloudgen.quality: choosing a tier applies it."""
    if _applying or settings.quality in ("", CUSTOM):
        return
    try:
        apply(settings.id_data, settings.quality)
    except KeyError:
        pass


def current(scene):
    """(name, tier) of the scene's Cloud Quality, or (None, None) for Custom / no tiers."""
    settings = _scene_settings(scene)
    name = settings.quality if settings is not None else CUSTOM
    if name in ("", CUSTOM):
        return None, None
    tier = tiers().get(name)
    return (name, tier) if tier is not None else (None, None)


def drift(scene) -> list:
    """Lines naming each render/preview setting that differs from the scene's tier."""
    name, tier = current(scene)
    if tier is None:
        return []
    label = tier_label(name, tier)
    out = []
    render = tier.get("render", {})
    c = scene.cycles
    if "samples" in render and int(c.samples) != int(render["samples"]):
        out.append(f"Samples {c.samples} ({label}: {int(render['samples'])})")
    if "step_rate" in render and hasattr(c, "volume_step_rate") \
            and abs(c.volume_step_rate - float(render["step_rate"])) > 1e-6:
        out.append(f"Step Rate {c.volume_step_rate:g} ({label}: {float(render['step_rate']):g})")
    size = tier.get("preview", {}).get("size")
    if size is not None and scene.cloudgen.preview_width != max(PREVIEW_MIN, min(PREVIEW_MAX, int(size))):
        out.append(f"Preview {scene.cloudgen.preview_width} px ({label}: {int(size)})")
    return out


# ---------------------------------------------------------------- bake arguments
def bake_arguments(tier_name, tier_bake, overrides: dict) -> tuple:
    """(resolution or None, extra CLI arguments) for `cloudgen bake`.

    tier_name/tier_bake: the tier (None for Custom); overrides: the bake settings the
    user set explicitly, among resolution, lod, tolerance, half. With a tier:
    `--quality NAME` plus only the overrides; else every value explicitly (the tier's,
    overridden) — also when an override cannot be said with flags (LOD on or full
    floats against a tier that turns them off)."""
    base = dict(DEFAULT_BAKE)
    if tier_bake:
        base.update({k: tier_bake[k] for k in DEFAULT_BAKE if k in tier_bake})
    eff = dict(base, **overrides)
    expressible = not (eff["lod"] and not base["lod"]) and not (not eff["half"] and base["half"])
    if tier_name and expressible:
        extra = ["--quality", tier_name]
        if "tolerance" in overrides:
            extra += ["--tolerance", repr(float(overrides["tolerance"]))]
        if "lod" in overrides and not overrides["lod"]:
            extra.append("--no-lod")
        if overrides.get("half"):
            extra.append("--half")
        return overrides.get("resolution"), extra
    extra = []
    if float(eff["tolerance"]) != 0.0:
        extra += ["--tolerance", repr(float(eff["tolerance"]))]
    if not eff["lod"]:
        extra.append("--no-lod")
    if eff["half"]:
        extra.append("--half")
    return int(eff["resolution"]), extra


def bake_values(tier_bake, overrides: dict) -> dict:
    """{resolution, lod, tolerance, half} a bake uses: Custom's defaults, the tier's
    bake settings, then the explicit overrides (what `--quality NAME` + flags mean)."""
    base = dict(DEFAULT_BAKE)
    if tier_bake:
        base.update({k: tier_bake[k] for k in DEFAULT_BAKE if k in tier_bake})
    return dict(base, **overrides)


def bake_summary(scene) -> str:
    """One line for the Bake panel: what a bake without overrides uses."""
    name, tier = current(scene)
    b = dict(DEFAULT_BAKE, **((tier or {}).get("bake") or {}))
    text = f"{int(b['resolution'])}³" + (", half" if b["half"] else "") \
        + ("" if b["lod"] else ", full detail") \
        + (f", tolerance {float(b['tolerance']):g}" if float(b["tolerance"]) else "")
    return f"{tier_label(name, tier) if tier else 'Custom'}: {text}"


# ---------------------------------------------------------------- operator and panel
class CLOUDGEN_OT_apply_quality(bpy.types.Operator):
    """Apply a cloud quality tier: Cycles samples and volume step rate, the preview size,
    and the settings Bake to VDB uses"""
    bl_idname = "cloudgen.apply_quality"
    bl_label = "Apply Cloud Quality"
    bl_options = {"REGISTER", "UNDO"}

    tier: bpy.props.EnumProperty(name="Tier", items=tier_items,
                                 description="Quality tier to apply (Custom: keep the settings)")

    def execute(self, context):
        if self.tier in ("", CUSTOM):
            context.scene.cloudgen.quality = CUSTOM
            return {"FINISHED"}
        try:
            tier = apply(context.scene, self.tier)
        except KeyError as exc:
            self.report({"ERROR"}, f"Cloud Quality: {exc.args[0]}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Cloud Quality: {tier_label(self.tier, tier)} applied")
        return {"FINISHED"}


class CLOUDGEN_PT_quality(SidebarPanel, bpy.types.Panel):
    bl_label = "Cloud Quality"
    bl_idname = "CLOUDGEN_PT_quality"
    bl_parent_id = "CLOUDGEN_PT_main"

    def draw(self, context):
        layout = self.layout
        scene = context.scene
        row = layout.row(align=True)
        row.prop(scene.cloudgen, "quality", text="")
        name, tier = current(scene)
        if tier is not None:
            op = row.operator(CLOUDGEN_OT_apply_quality.bl_idname, text="", icon="FILE_REFRESH")
            op.tier = name
            desc = str(tier.get("description", "")).strip()
            if desc:
                wrapped_label(layout, desc, context=context)
            lines = measured_lines(tier)
            for line in lines or ["not measured yet"]:
                wrapped_label(layout, line, "TIME", context)
            changed = drift(scene)
            if changed:
                wrapped_label(layout, "Changed by hand: " + "; ".join(changed), "INFO", context)
        elif tiers_error():
            wrapped_label(layout, tiers_error(), "ERROR", context)


classes = (CLOUDGEN_OT_apply_quality, CLOUDGEN_PT_quality)
