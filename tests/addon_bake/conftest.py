"""Bake tests. test_bake_process.py needs only the CLI; the others run inside the
bpy wheel (Blender 4.5 in .venv) against the packaged add-on build/addon/cloudgen
(repackaged when addon/ or osl/ is newer), and are skipped without bpy unless
CLOUDGEN_REQUIRE_BPY=1. The add-on is disabled in teardown, which unregisters
every class it registered (the 4.5 wheel hangs at exit while an operator class
is registered)."""
import pathlib

import addon_package
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
ADDON_PARENT = ROOT / "build" / "addon"
PACKAGE = ADDON_PARENT / "cloudgen"
HERE = pathlib.Path(__file__).parent


def _raise(exc):
    raise exc


@pytest.fixture(scope="module")
def bake_addon():
    """The enabled add-on (its bake operators and panel included); disabled afterwards."""
    import addon_utils

    addon_package.ensure()
    mod = addon_utils.enable("cloudgen", default_set=False, handle_error=_raise)
    assert mod is not None, "addon_utils.enable('cloudgen') failed"
    yield mod
    addon_utils.disable("cloudgen", default_set=False, handle_error=_raise)


@pytest.fixture(params=["blender", "cli"])
def built_cli(bake_addon, monkeypatch, request):
    """Both bake paths: inside Blender (bake_local.py, no CLI configured) and build/bin/cloudgen."""
    from cloudgen import bridge

    cli = ROOT / "build" / "bin" / "cloudgen"
    if request.param == "cli":
        monkeypatch.setattr(bridge, "cloudgen_executable", lambda: str(cli))
    else:
        monkeypatch.setattr(bridge, "cloudgen_executable", lambda: None)
    return request.param
