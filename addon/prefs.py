"""The add-on's preferences (Edit → Preferences → Add-ons → cloudgen).

- cloudgen CLI: an explicit path to the `cloudgen` command-line tool. Empty (the
  default): Bake to VDB bakes inside Blender (bake_local.py); set: bakes run that
  CLI, which Fit to Camera needs. The add-on never looks for `cloudgen` on PATH.
- Dask scheduler / Python: a Bake Frame Range goes to the distributed runner
  (`<python> -m cloudgen_dask bake --scheduler ADDRESS ...`, docs/distributed.md)
  when the address is set; empty: the local bake.
"""
import bpy

_PACKAGE = __package__  # "cloudgen" (legacy add-on) or "bl_ext.<repo>.cloudgen" (extension)


class CLOUDGEN_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = _PACKAGE

    cli_path: bpy.props.StringProperty(
        name="cloudgen CLI", subtype="FILE_PATH", default="",
        description="The cloudgen command-line tool to bake with (needed for Fit to Camera); "
                    "empty: bake inside Blender")
    dask_scheduler: bpy.props.StringProperty(
        name="Dask Scheduler", default="",
        description="tcp://HOST:PORT of a Dask scheduler: Bake Frame Range runs there; "
                    "empty: bake on this computer")
    dask_python: bpy.props.StringProperty(
        name="Runner Python", subtype="FILE_PATH", default="",
        description="The Python that has cloudgen_dask installed (runs -m cloudgen_dask bake)")

    def draw(self, context):
        col = self.layout.column()
        col.prop(self, "cli_path")
        col.label(text="Empty: Bake to VDB runs inside Blender (no Fit to Camera)")
        col.separator()
        col.prop(self, "dask_scheduler")
        col.prop(self, "dask_python")


def get():
    """This add-on's preferences, or None (not registered, e.g. a script importing modules)."""
    try:
        addon = bpy.context.preferences.addons.get(_PACKAGE)
    except AttributeError:
        return None
    return addon.preferences if addon is not None else None


def cli_path() -> str:
    p = get()
    return bpy.path.abspath(p.cli_path) if p is not None and p.cli_path else ""


def dask() -> tuple:
    """(scheduler address, python) or ("", "") when no scheduler is set."""
    p = get()
    if p is None or not p.dask_scheduler.strip():
        return "", ""
    return p.dask_scheduler.strip(), (bpy.path.abspath(p.dask_python) if p.dask_python else "")


classes = (CLOUDGEN_AP_preferences,)
