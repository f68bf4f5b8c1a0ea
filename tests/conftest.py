"""Shared by every test folder. The folders blender/, addon/ and addon_bake/ run
inside Blender's Python (the bpy wheel: Blender 4.5 in .venv, 5.0 in
.venv-blender5); bpy is imported once per process, here. Without bpy their
tests are skipped — unless CLOUDGEN_REQUIRE_BPY=1 (scripts/test.sh sets it),
in which case a missing bpy is an error."""
import os
import pathlib

import pytest

try:
    import bpy  # noqa: F401
    HAVE_BPY = True
except ImportError:
    HAVE_BPY = False

TESTS = pathlib.Path(__file__).resolve().parent
NEEDS_BPY = ("blender", "addon", "addon_bake")
RUNS_WITHOUT_BPY = {"test_bake_process.py", "test_osl_lint.py"}  # CLI-only / plain-text checks


def needs_bpy(path: pathlib.Path) -> bool:
    try:
        folder = path.resolve().relative_to(TESTS).parts[0]
    except ValueError:
        return False
    return folder in NEEDS_BPY and path.name not in RUNS_WITHOUT_BPY


def pytest_collection_modifyitems(config, items):
    if HAVE_BPY:
        return
    targets = [item for item in items if needs_bpy(pathlib.Path(str(item.fspath)))]
    if not targets:
        return
    if os.environ.get("CLOUDGEN_REQUIRE_BPY") == "1":
        raise pytest.UsageError("CLOUDGEN_REQUIRE_BPY=1 but `import bpy` failed: run scripts/setup.sh")
    skip = pytest.mark.skip(reason="bpy (Blender as a Python module) is not installed")
    for item in targets:
        item.add_marker(skip)


@pytest.fixture
def uniform_world():
    """make(scene, radiance): gives the scene a uniform white world of that radiance, which a
    light meter reads exactly (Cycles samples a constant background without noise)."""
    def make(scene, radiance):
        import bpy

        world = bpy.data.worlds.new("White")
        world.use_nodes = True
        bg = world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        bg.inputs["Strength"].default_value = radiance
        scene.world = world
        return world

    return make
