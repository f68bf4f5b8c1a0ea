"""The sidebar tab every cloudgen panel lives in (ui.py, quality.py, bake_panel.py).
No imports of the add-on's own modules: any of them can use it."""


class SidebarPanel:
    """A panel in the 3D view sidebar's Cloud tab."""
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Cloud"
