"""Reference render of the default cumulus, procedural OSL in Cycles on the CPU,
compared with a stored image using the thresholds of Blender's own render
tests: a pixel fails when it differs by more than 0.016 (in any channel, on
the 0..1 scale of the 8-bit PNG), and the test fails when more than 1 % of
the pixels fail. On failure a difference image (|a-b| × 10) is written next
to the test's output and its path printed.

Regenerate the reference (after an intended change of the model or the
scene, and look at it): CLOUDGEN_UPDATE_GOLDEN=1 pytest tests/blender/test_osl_render.py
(ref.png is Blender 4.5's; ref_blender5.png Blender 5.0's, made by scripts/test_blender5.sh).
"""
import os
import pathlib
import shutil
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from scene_helpers import load_rgb  # noqa: E402  (tests/ is on sys.path: tests/conftest.py)

GOLDEN = ROOT / "tests" / "golden" / "cumulus_osl"
PIXEL_THRESHOLD = 0.016
FAIL_FRACTION = 0.01
RENDER_ARGS = ["--preset", "cumulus", "--size", "128x128", "--samples", "16", "--seed", "7", "--light", "studio"]


def test_cumulus_reference_render(tmp_path):
    import render_cloud

    out = tmp_path / "cumulus.png"
    args = render_cloud.parse_args(RENDER_ARGS + ["--output", str(out)])
    scene = render_cloud.build_scene(render_cloud.resolve_params(args), args)
    seconds = render_cloud.render(scene, out)
    print(f"\nreference render: 128x128, 16 spp, {seconds:.1f} s")
    import bpy

    # Blender 5 renders volumes differently (null scattering, majorant octree):
    # same cloud, different noise pattern and slightly different energy — its own reference.
    ref = GOLDEN / ("ref.png" if bpy.app.version[0] < 5 else f"ref_blender{bpy.app.version[0]}.png")
    if os.environ.get("CLOUDGEN_UPDATE_GOLDEN") == "1" or not ref.exists():
        assert os.environ.get("CLOUDGEN_UPDATE_GOLDEN") == "1", f"no reference image at {ref}"
        GOLDEN.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(out, ref)
    got, want = load_rgb(out), load_rgb(ref)
    assert got.shape == want.shape, f"size {got.shape} != reference {want.shape}"
    diff = np.abs(got - want).max(axis=-1)
    failed = float((diff > PIXEL_THRESHOLD).mean())
    # the cloud must be there at all: a sky-only image would be a useless reference
    assert float((np.abs(want - want[0, 0]).max(axis=-1) > 0.1).mean()) > 0.05, "reference shows no cloud"
    if failed > FAIL_FRACTION:
        diff_path = tmp_path / "cumulus_diff.npy"
        np.save(diff_path, diff)
        import bpy

        img = bpy.data.images.new("diff", got.shape[1], got.shape[0])
        rgba = np.concatenate([np.repeat(np.clip(diff * 10, 0, 1)[..., None], 3, -1),
                               np.ones(diff.shape + (1,), np.float32)], -1)
        img.pixels[:] = rgba.ravel()
        img.filepath_raw = str(tmp_path / "cumulus_diff.png")
        img.file_format = "PNG"
        img.save()
        raise AssertionError(f"{failed:.2%} of pixels differ by more than {PIXEL_THRESHOLD} "
                             f"(allowed {FAIL_FRACTION:.0%}); max {diff.max():.3f}; "
                             f"difference image {tmp_path / 'cumulus_diff.png'}, render {out}")
