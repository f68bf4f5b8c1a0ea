"""Add-on tests, inside the bpy wheel (Blender 4.5 in .venv). They test the
packaged add-on, build/addon/cloudgen (scripts/package_addon.py; repackaged
here when addon/ or osl/ is newer than the package), enabled with
addon_utils from a sys.path entry, and disabled in teardown — the 4.5 wheel
hangs at exit while an operator class or a bpy.app.timers timer is still
registered.

Without bpy the directory is skipped, unless CLOUDGEN_REQUIRE_BPY=1.
"""
import pathlib

import addon_package
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
ADDON_PARENT = ROOT / "build" / "addon"
PACKAGE = ADDON_PARENT / "cloudgen"


@pytest.fixture(scope="session")
def package():
    addon_package.ensure()
    return PACKAGE


@pytest.fixture(scope="module")
def addon(package):
    """The enabled add-on module; disabled (everything unregistered) afterwards."""
    import addon_utils

    mod = addon_utils.enable("cloudgen", default_set=False, handle_error=_raise)
    assert mod is not None, "addon_utils.enable('cloudgen') failed"
    yield mod
    addon_utils.disable("cloudgen", default_set=False, handle_error=_raise)


def _raise(exc):
    raise exc


@pytest.fixture
def scene(addon):
    """An empty scene (add-ons stay enabled) set up by the add-on's Render Settings
    helper, then made small and exact: 4 spp, no denoising, CPU + OSL."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.cloudgen.render_settings(denoise=False, volume_bounces=4)  # not raised by Add Cloud
    sc = bpy.context.scene
    sc.cycles.samples = 4
    sc.cycles.seed = 1
    sc.render.resolution_x, sc.render.resolution_y = 48, 36
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    return sc
