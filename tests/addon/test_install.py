"""The zip installs both ways into a fresh user directory (subprocesses, so the
user paths are the temporary ones): as a 4.2+ extension (bl_ext.user_default.cloudgen,
relative imports only) and as a legacy add-on (Install from Disk)."""
import os
import subprocess
import sys
import textwrap

import pytest
from addon_helpers import ROOT

EXTENSION = textwrap.dedent("""
    import sys, bpy, addon_utils
    r = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default",
                                                 enable_on_install=True)
    assert r == {"FINISHED"}, r
    name = "bl_ext.user_default.cloudgen"
    mod = sys.modules[name]
    assert mod.bridge.error() is None, mod.bridge.error()
    assert mod.bridge.native().__file__.startswith(sys.argv[2]), mod.bridge.native().__file__
    assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
    assert mod.bridge.cloudgen_executable().startswith(sys.argv[2])
    addon_utils.disable(name, default_set=False)
    assert not hasattr(bpy.types, "CLOUDGEN_OT_add_cloud")
    print("OK")
""")

LEGACY = textwrap.dedent("""
    import sys, bpy, addon_utils
    assert bpy.ops.preferences.addon_install(filepath=sys.argv[1]) == {"FINISHED"}
    mod = addon_utils.enable("cloudgen", default_set=False)
    assert mod is not None and mod.__file__.startswith(sys.argv[2]), mod
    assert mod.bridge.error() is None, mod.bridge.error()
    assert bpy.ops.cloudgen.add_cloud(cloud_type="stratus") == {"FINISHED"}
    addon_utils.disable("cloudgen", default_set=False)
    assert not hasattr(bpy.types, "CLOUDGEN_OT_add_cloud")
    print("OK")
""")


@pytest.mark.parametrize("how", ["extension", "legacy"])
def test_zip_installs(package, tmp_path, how):
    user = tmp_path / "user"
    user.mkdir()
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user))
    zip_path = ROOT / "build" / "cloudgen-addon.zip"
    script = EXTENSION if how == "extension" else LEGACY
    run = subprocess.run([sys.executable, "-c", script, str(zip_path), str(user)], env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "OK" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]
