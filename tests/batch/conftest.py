"""The batch tests' shared set-up: Debian's Blender 3.4 (/usr/bin/blender) with the packaged
add-on in isolated user folders. Skipped without it unless CLOUDGEN_REQUIRE_BLENDER=1."""
import os
import pathlib

import addon_package
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "build" / "addon" / "cloudgen"


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """Isolated user dirs with the packaged add-on linked in; package rebuilt when stale."""
    base = tmp_path_factory.mktemp("b34")
    addon_package.ensure()
    (base / "scripts" / "addons").mkdir(parents=True)
    (base / "scripts" / "addons" / "cloudgen").symlink_to(PACKAGE)
    (base / "config").mkdir()
    (base / "out").mkdir()
    path = os.pathsep.join(d for d in os.environ.get("PATH", "").split(os.pathsep)
                           if d and not os.path.exists(os.path.join(d, "cloudgen")))
    e = dict(os.environ, BLENDER_USER_SCRIPTS=str(base / "scripts"), BLENDER_USER_CONFIG=str(base / "config"),
             PATH=path)
    return base, e
