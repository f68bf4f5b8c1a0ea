"""The scenes of the accuracy sweep and their render settings.

Each scene is scripts/render_cloud.py's scene (build_scene / frame_camera: the
cloud box, a 50 mm camera framed from the box, a sun, a blue sky, Cycles CPU,
denoising off) for one preset. Render settings:

- BASE: what every swept point uses unless its knob changes it — render_cloud's
  defaults: 64 samples, the preset's material step rate, render step rate
  (scene.cycles.volume_step_rate) 1.
- REFERENCE: the procedural OSL material with a finer step (render step rate
  0.125, below every swept point) and many samples, rendered with seeds 1 and
  2; their average is the reference image, their difference the noise floor.
  Samples per scene are chosen so one reference render stays under ~4 minutes
  on the 2-core machine.
- REFERENCE_50: the Blender 5.0 reference for the volume_biased knob: 5.0's
  default unbiased (null-scattering) volume integrator, which has no step size.
"""
from __future__ import annotations

IMAGE_SIZE = (128, 96)
QUICK_IMAGE_SIZE = (32, 24)
SWEEP_SEED = 0          # every swept render (the references use 1 and 2)
REF_SEEDS = (1, 2)

SCENES = {
    # the description is copied into the results: it names the box the cached points were
    # measured in (2026-11-22). The preset's box is 5 x 5 x 3 since 2026-11-29; change it here
    # when the scene is measured again (docs/accuracy.md, "Dated")
    "cumulus": {
        "preset": "cumulus",
        "description": "Fair-weather cumulus (4 x 4 x 3 box) seen from the side, slightly below its middle.",
    },
    "stratocumulus": {
        "preset": "stratocumulus",
        "description": ("A wide thin layer (12 x 12 x 1.6 box) seen from below at an angle, "
                        "its far edge low in the frame."),
    },
    "cirrus": {
        "preset": "cirrus",
        "description": "High thin wispy streaks (12 x 12 x 0.6 box) seen from below; material step rate 0.5.",
    },
    # not in the default run (--scenes cumulus_closeup): a close-up where a camera-aware
    # bake can spend its voxels where the camera looks
    "cumulus_closeup": {
        "preset": "cumulus",
        "description": ("The cumulus scene's camera zoomed 3x onto the upper front of the cloud "
                        "(render_cloud --zoom 3 --aim 0.5,0.3,0.7)."),
        "render_args": ["--zoom", "3", "--aim", "0.5,0.3,0.7"],
        "extra": True,
        "knobs": ["procedural", "bake_resolution", "camera_aware"],
    },
}

BASE = {"samples": 64, "step_rate": 1.0}
REFERENCE = {
    "cumulus": {"samples": 80, "step_rate": 0.125},
    "cumulus_closeup": {"samples": 40, "step_rate": 0.125},  # the cloud fills the frame: ~4x the cost per sample
    "stratocumulus": {"samples": 96, "step_rate": 0.125},
    "cirrus": {"samples": 256, "step_rate": 0.125},
}
REFERENCE_50 = {"cumulus": {"samples": 192, "volume_biased": "off"},
                "stratocumulus": {"samples": 192, "volume_biased": "off"},
                "cirrus": {"samples": 384, "volume_biased": "off"}}

QUICK_BASE = {"samples": 4, "step_rate": 1.0}
QUICK_REFERENCE = {"samples": 16, "step_rate": 0.25}
QUICK_REFERENCE_50 = {"samples": 16, "volume_biased": "off"}


def size_arg(size):
    return f"{size[0]}x{size[1]}"
