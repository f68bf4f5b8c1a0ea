"""Tests that run inside Blender's Python: the `bpy` wheel (Blender 4.5 in .venv;
5.0 in .venv-blender5 via scripts/test_blender5.sh).

Without bpy the whole directory is skipped — unless CLOUDGEN_REQUIRE_BPY=1
(scripts/test.sh sets it), in which case a missing bpy is an error.
"""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "osl"))


@pytest.fixture
def empty_scene():
    """A factory-empty Cycles scene on the CPU with OSL on and denoising off."""
    import blender_nodes
    import bpy

    blender_nodes.ensure_oslquery_importable()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.shading_system = True
    scene.cycles.use_denoising = False
    scene.view_settings.view_transform = "Standard"
    return scene
