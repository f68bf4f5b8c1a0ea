"""Time the procedural OSL render of the default cumulus in the running
Blender (bpy wheel), with and without Cloud Main's early exit, and the time to
compile the shaders.

Usage: .venv/bin/python bench/osl_render.py [--runs 3] [--size 128x128] [--samples 16]
       .venv-blender5/bin/python bench/osl_render.py ...    (Blender 5.0)
Prints one JSON object; reports the best (and median) of --runs renders each.
"""
import argparse
import json
import os
import pathlib
import statistics
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "osl"))


def compile_seconds():
    import _cycles
    import flatten

    times = []
    with tempfile.TemporaryDirectory() as d:
        for name in flatten.SHADERS:
            src, oso = os.path.join(d, name + ".osl"), os.path.join(d, name + ".oso")
            pathlib.Path(src).write_text(flatten.shader_source(name))
            t0 = time.perf_counter()
            assert _cycles.osl_compile(src, oso)
            times.append(time.perf_counter() - t0)
    return dict(zip(flatten.SHADERS, times))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--samples", type=int, default=16)
    opts = ap.parse_args()
    import bpy
    import render_cloud

    result = {"blender": bpy.app.version_string, "size": opts.size, "samples": opts.samples,
              "runs": opts.runs, "compile_s": compile_seconds(), "cpu_count": os.cpu_count()}
    with tempfile.TemporaryDirectory() as d:
        for label, extra in (("early_exit", []), ("no_early_exit", ["--no-early-exit"])):
            times = []
            for run in range(opts.runs):
                args = render_cloud.parse_args(["--preset", "cumulus", "--size", opts.size, "--samples",
                                                str(opts.samples), "--seed", "7", "--output",
                                                os.path.join(d, f"{label}_{run}.png")] + extra)
                scene = render_cloud.build_scene(render_cloud.resolve_params(args), args)
                times.append(render_cloud.render(scene, args.output))
            result[label] = {"best_s": min(times), "median_s": statistics.median(times), "all_s": times}
    result["early_exit_speedup"] = result["no_early_exit"]["best_s"] / result["early_exit"]["best_s"]
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
