"""The sidebar tab every cloudgen panel lives in (ui.py, quality.py, bake_panel.py),
and the two text helpers of artist-facing text. No imports of the add-on's own
modules: any of them can use it."""
import textwrap

# Characters that fit one label line of the sidebar at its default width (Blender 3.4-4.5:
# about 300 px at UI scale 1 minus the panel margins and an icon; measured on screenshots).
DEFAULT_CHARS = 34


def tooltip(text) -> str:
    """A description as Blender wants it: no trailing period (Blender adds one)."""
    return str(text or "").strip().rstrip(".").strip()


def chars_per_line(context=None) -> int:
    """Label characters that fit the sidebar's current width (DEFAULT_CHARS without a region)."""
    region = getattr(context, "region", None) if context is not None else None
    width = getattr(region, "width", 0) or 0
    if width <= 0:
        return DEFAULT_CHARS
    scale = getattr(getattr(getattr(context, "preferences", None), "view", None), "ui_scale", 1.0) or 1.0
    return max(16, int((width / scale - 50) / 7.5))


def wrapped_label(layout, text, icon="NONE", context=None):
    """text as one or more labels, none wider than the sidebar (the icon on the first only)."""
    lines = textwrap.wrap(str(text), chars_per_line(context)) or [""]
    col = layout.column(align=True)
    for i, line in enumerate(lines):
        col.label(text=line, icon=icon if i == 0 else "BLANK1" if icon != "NONE" else "NONE")


class SidebarPanel:
    """A panel in the 3D view sidebar's Cloud tab."""
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Cloud"
