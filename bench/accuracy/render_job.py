"""One render of the accuracy sweep, in its own process (so the parent can read
this process's peak RSS with os.wait4).

Usage: python bench/accuracy/render_job.py [--scene-step-rate R] [--volume-biased on|off]
           <scripts/render_cloud.py arguments: --preset/--params, --output X.exr, --size,
            --samples, --seed, --vdb FILE, --step-rate ...>

Builds render_cloud.py's scene, sets the render-wide Cycles settings given here
(scene.cycles.volume_step_rate multiplies every material's step rate;
scene.cycles.volume_biased exists from Blender 5.0 on), renders, and prints one
line of JSON: {"render_s": wall seconds of bpy.ops.render.render alone (no bpy
import, no scene building), "build_s", "blender": version, "output": path}.
Exits with os._exit(0): the bpy 4.5 wheel can hang at interpreter exit.
"""
import argparse
import json
import os
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene-step-rate", type=float, default=None)
    ap.add_argument("--volume-biased", choices=("on", "off"), default=None)
    own, rest = ap.parse_known_args()
    t0 = time.perf_counter()
    import bpy
    import render_cloud

    args = render_cloud.parse_args(rest)
    t1 = time.perf_counter()
    scene = render_cloud.build_scene(render_cloud.resolve_params(args), args)
    if own.scene_step_rate is not None:
        scene.cycles.volume_step_rate = own.scene_step_rate
    if own.volume_biased is not None:
        if not hasattr(scene.cycles, "volume_biased"):
            raise SystemExit(f"render_job: Blender {bpy.app.version_string} has no volume_biased")
        scene.cycles.volume_biased = own.volume_biased == "on"
    build_s = time.perf_counter() - t1
    seconds = render_cloud.render(scene, args.output)
    result = {"render_s": seconds, "build_s": build_s, "import_s": t1 - t0,
              "blender": bpy.app.version_string, "output": str(args.output),
              "volume_step_rate": scene.cycles.volume_step_rate,
              "volume_biased": getattr(scene.cycles, "volume_biased", None)}
    sys.stdout.write("RENDER_JOB " + json.dumps(result) + "\n")
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


if __name__ == "__main__":
    try:
        main()
    except SystemExit as exc:
        sys.stdout.flush()
        sys.stderr.write(f"{exc}\n")
        sys.stderr.flush()
        os._exit(exc.code if isinstance(exc.code, int) else 2)
    except BaseException:
        import traceback
        traceback.print_exc()
        sys.stderr.flush()
        os._exit(1)
