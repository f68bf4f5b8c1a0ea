"""The zip installs both ways into a fresh user directory (subprocesses, so the
user paths are the temporary ones): as a 4.2+ extension (build/cloudgen-extension.zip,
built and validated by Blender's own extension tool; bl_ext.user_default.cloudgen,
relative imports only) and as a legacy add-on (build/cloudgen-addon.zip, Install
from Disk). Both then bake a cloud inside Blender with no cloudgen executable
anywhere: none in the package, and a `cloudgen` put first on PATH is never run
(it would leave a marker file). Nothing the add-on does writes into its own folder
(file list and modification times compared, Python's __pycache__ aside)."""
import os
import subprocess
import sys
import textwrap

import pytest
from addon_helpers import ROOT

COMMON = textwrap.dedent("""
    import os, pathlib, sys, bpy, addon_utils

    def snapshot(folder):
        return {str(p.relative_to(folder)): p.stat().st_mtime_ns for p in pathlib.Path(folder).rglob("*")
                if "__pycache__" not in p.parts}

    def executables(folder):
        return [str(p) for p in pathlib.Path(folder).rglob("*")
                if p.is_file() and os.access(p, os.X_OK) and p.suffix not in (".so", ".pyd")]

    def bake_here(mod, out):
        assert mod.bridge.cloudgen_executable() is None, mod.bridge.cloudgen_executable()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "i.blend"))
        assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
        assert bpy.ops.cloudgen.bake_vdb(resolution=12) == {"FINISHED"}
        assert os.path.getsize(os.path.join(out, "cloudgen", "Cumulus.vdb")) > 0
        assert not os.path.exists(os.environ["FAKE_CLI_MARKER"]), "the cloudgen on PATH was run"
""")

EXTENSION = COMMON + textwrap.dedent("""
    r = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default",
                                                 enable_on_install=True)
    assert r == {"FINISHED"}, r
    name = "bl_ext.user_default.cloudgen"
    mod = sys.modules[name]
    assert mod.bridge.error() is None, mod.bridge.error()
    assert mod.bridge.native().__file__.startswith(sys.argv[2]), mod.bridge.native().__file__
    folder = os.path.dirname(mod.__file__)
    before = snapshot(folder)
    assert not executables(folder), executables(folder)
    bake_here(mod, sys.argv[3])
    assert snapshot(folder) == before, "the add-on wrote into its own folder"
    addon_utils.disable(name, default_set=False)
    assert not hasattr(bpy.types, "CLOUDGEN_OT_add_cloud")
    print("OK")
""")

LEGACY = COMMON + textwrap.dedent("""
    assert bpy.ops.preferences.addon_install(filepath=sys.argv[1]) == {"FINISHED"}
    mod = addon_utils.enable("cloudgen", default_set=False)
    assert mod is not None and mod.__file__.startswith(sys.argv[2]), mod
    assert mod.bridge.error() is None, mod.bridge.error()
    folder = os.path.dirname(mod.__file__)
    before = snapshot(folder)
    assert not executables(folder), executables(folder)
    assert bpy.ops.cloudgen.add_cloud(cloud_type="stratus") == {"FINISHED"}
    bake_here(mod, sys.argv[3])
    assert snapshot(folder) == before, "the add-on wrote into its own folder"
    addon_utils.disable("cloudgen", default_set=False)
    assert not hasattr(bpy.types, "CLOUDGEN_OT_add_cloud")
    print("OK")
""")


@pytest.mark.parametrize("how", ["extension", "legacy"])
def test_zip_installs(package, tmp_path, how):
    user = tmp_path / "user"
    user.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    fake_bin = tmp_path / "bin"
    fake_bin.mkdir()
    marker = tmp_path / "fake-cli-ran"
    fake = fake_bin / "cloudgen"
    fake.write_text(f"#!/bin/sh\ntouch {marker}\nexit 3\n")
    fake.chmod(0o755)
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user), FAKE_CLI_MARKER=str(marker),
               PATH=f"{fake_bin}{os.pathsep}{os.environ.get('PATH', '')}")
    name = "cloudgen-extension.zip" if how == "extension" else "cloudgen-addon.zip"
    zip_path = ROOT / "build" / name
    assert zip_path.is_file(), f"{zip_path} missing (scripts/package_addon.py builds it)"
    script = EXTENSION if how == "extension" else LEGACY
    run = subprocess.run([sys.executable, "-c", script, str(zip_path), str(user), str(out)], env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0 and "OK" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]


@pytest.mark.parametrize("zip_name", ["cloudgen-addon.zip", "cloudgen-extension.zip"])
def test_zip_carries_no_executable_and_a_license(package, zip_name):
    import zipfile

    with zipfile.ZipFile(ROOT / "build" / zip_name) as z:
        names = z.namelist()
        executable = [i.filename for i in z.infolist()
                      if (i.external_attr >> 16) & 0o111 and not i.filename.endswith(".so")]
    assert not [n for n in names if "/bin/" in n or n.startswith("bin/")], names
    assert not executable, f"executable files in {zip_name}: {executable}"
    assert any(n.endswith("LICENSE") for n in names), f"no LICENSE in {zip_name}"


def test_blender_validates_the_extension(package):
    """Blender's own validator (blender_ext.py validate, as `blender --command extension
    validate`) accepts the package, and the manifest names its license and a website."""
    import importlib.util
    import pathlib

    spec = importlib.util.spec_from_file_location("package_addon", ROOT / "scripts" / "package_addon.py")
    pa = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pa)
    commands = pa.extension_commands(ROOT / "build" / "addon" / "cloudgen", pathlib.Path("/nonexistent"))
    assert commands is not None, "no blender_ext.py in the bpy wheel"
    run = subprocess.run(commands[0], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr
    manifest = (ROOT / "addon" / "blender_manifest.toml").read_text()
    assert 'license = ["SPDX:GPL-3.0-or-later"]' in manifest and "website = " in manifest
    assert "GNU GENERAL PUBLIC LICENSE" in (ROOT / "LICENSE").read_text()[:200]
