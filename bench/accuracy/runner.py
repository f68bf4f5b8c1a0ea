"""The sweep's child processes: renders (render_job.py in a Blender Python), bakes
(the `cloudgen bake --json` CLI, read with addon/cli_events.py) and the export of
a scene's camera file. Each returns its wall times and peak RSS (os.wait4).
"""
from __future__ import annotations

import importlib.util
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

from accuracy import scenes
from accuracy.config import PY45, PY50, RENDER_JOB, ROOT


def _load_cli_events():
    """addon/cli_events.py, the one reader of the CLI's JSON lines (no bpy, no relative imports)."""
    if "cli_events" in sys.modules:
        return sys.modules["cli_events"]
    spec = importlib.util.spec_from_file_location("cli_events", ROOT / "addon" / "cli_events.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["cli_events"] = mod
    spec.loader.exec_module(mod)
    return mod


cli_events = _load_cli_events()


def log(msg):
    print(time.strftime("%H:%M:%S"), msg, flush=True)


def run_child(cmd, env=None):
    """(returncode, stdout, stderr, wall seconds, peak RSS MiB) of a child process."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen([str(c) for c in cmd], stdout=out, stderr=err, cwd=ROOT, env=env)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return (p.returncode, out.read().decode(errors="replace"), err.read().decode(errors="replace"),
                wall, ru.ru_maxrss / 1024.0)


# ----------------------------------------------------------------- renders --


def render_cmd(scene, spec, output, blender="4.5", vdb=None, params_file=None):
    py = PY50 if blender == "5.0" else PY45
    cmd = [py, RENDER_JOB]
    if spec.get("step_rate") is not None:
        cmd += ["--scene-step-rate", spec["step_rate"]]
    if spec.get("volume_biased"):
        cmd += ["--volume-biased", spec["volume_biased"]]
    cmd += (["--params", params_file] if params_file else ["--preset", scenes.SCENES[scene]["preset"]])
    cmd += scenes.SCENES[scene].get("render_args", [])
    cmd += ["--size", scenes.size_arg(spec["size"]), "--samples", spec["samples"], "--seed", spec["seed"],
            "--output", output]
    if vdb:
        cmd += ["--vdb", vdb]
    return cmd


def render(scene, spec, output, blender, runs, vdb=None, workdir=None):
    """Render `runs` times (same seed: the same image); timings of each."""
    params_file = None
    if spec.get("params"):
        params_file = pathlib.Path(workdir) / "params.json"
        params_file.write_text(json.dumps(dict({"preset": scenes.SCENES[scene]["preset"]}, **spec["params"])))
    times, peaks, version = [], [], None
    for _ in range(runs):
        rc, out, err, wall, peak = run_child(render_cmd(scene, spec, output, blender, vdb, params_file))
        m = re.search(r"^RENDER_JOB (.*)$", out, re.M)
        if rc != 0 or not m:
            raise RuntimeError(f"render failed (exit {rc}): {err[-2000:]}")
        res = json.loads(m.group(1))
        times.append(res["render_s"])
        peaks.append(peak)
        version = res["blender"]
    return {"render_s": min(times), "render_s_all": times, "peak_mib": max(peaks), "version": version}


# ------------------------------------------------------------------- bakes --


def bake_cmd(cfg, scene, spec, output, camera_file=None):
    """The `cloudgen bake` command of a bake specification (without --json)."""
    cmd = [cfg.cloudgen, "bake", "--quiet", "--preset", scenes.SCENES[scene]["preset"], "--output", output]
    if spec.get("camera"):
        cmd += ["--camera", camera_file]
        if spec.get("resolution"):
            cmd += ["--resolution", spec["resolution"]]
    elif spec.get("quality") and "--quality" in cfg.cli_help():
        cmd += ["--quality", spec["quality"]]
    else:
        cmd += ["--resolution", spec["resolution"]]
        if spec.get("tolerance"):
            cmd += ["--tolerance", repr(spec["tolerance"])]
        if spec.get("half"):
            cmd += ["--half"]
        if not spec.get("lod", True):
            cmd += ["--no-lod"]
        if not spec.get("skip", True):
            cmd += ["--no-skip"]
    return cmd


def bake_events(stdout):
    """cli_events.BakeEvents of a finished run's stdout (protocol errors raised)."""
    events = cli_events.BakeEvents()
    for line in stdout.splitlines():
        events.feed(line)
    return events


def camera_figures(events):
    """camera_voxel, visible_tiles, total_tiles of a camera-aware bake (from its wrote
    event: visible = tiles_total - tiles_culled); {} for a bake without --camera."""
    if events.camera is None or not events.written:
        return {}
    w = events.written[-1]
    return {"camera_voxel": float(w["voxel"]), "visible_tiles": int(w["tiles_total"]) - int(w["tiles_culled"]),
            "total_tiles": int(w["tiles_total"])}


def bake(cfg, scene, spec, output, workdir):
    """Bake cfg.bake_runs times: best time, peak RSS, file size, the command, camera figures."""
    if "--json" not in cfg.cli_help():
        raise RuntimeError(f"{cfg.cloudgen} bake has no --json (docs/cli_protocol.md): rebuild the CLI")
    camera_file = None
    if spec.get("camera"):
        camera_file = pathlib.Path(workdir) / "camera.json"
        export_camera(cfg, scene, camera_file, spec["pixels_per_voxel"], spec.get("margin"))
    cmd = bake_cmd(cfg, scene, spec, output, camera_file)
    times, peaks, events = [], [], None
    for _ in range(cfg.bake_runs):
        rc, out, err, wall, peak = run_child(cmd + ["--json"])
        try:
            events = bake_events(out)
        except cli_events.ProtocolError as exc:
            raise RuntimeError(f"bake: {exc}: {' '.join(map(str, cmd))}\n{err[-1000:]}") from None
        if rc != 0 or events.error or not events.written:
            why = events.error["message"] if events.error else f"no file written\n{out[-1000:]}{err[-1000:]}"
            raise RuntimeError(f"bake failed (exit {rc}): {' '.join(map(str, cmd))}\n{why}")
        times.append(wall)
        peaks.append(peak)
    res = {"bake_s": min(times), "bake_s_all": times, "bake_peak_mib": max(peaks),
           "file_mib": os.path.getsize(output) / 2 ** 20,
           "bake_cmd": " ".join(map(str, cmd[1:])).replace(str(workdir) + "/", "")}
    res.update(camera_figures(events))
    return res


def export_camera(cfg, scene, path, ppv, margin):
    """CAMERA.json of the scene's camera (addon/camera_fit.py inside the bpy scene)."""
    code = (
        "import sys, json, os; sys.path[:0] = [%r, %r]\n"
        "import bpy, render_cloud, camera_fit\n"
        "a = render_cloud.parse_args(['--preset', %r, '--size', %r, '--output', 'x.exr'] + %r)\n"
        "s = render_cloud.build_scene(render_cloud.resolve_params(a), a)\n"
        "bpy.context.view_layer.update()  # matrix_world of the camera just placed\n"
        "d = camera_fit.camera_json(s, s.camera, bpy.data.objects['Cloud'], margin=%r, pixels_per_voxel=%r)\n"
        "open(%r, 'w').write(json.dumps(d, indent=1)); sys.stdout.flush(); os._exit(0)\n"
    ) % (str(ROOT / "scripts"), str(ROOT / "addon"), scenes.SCENES[scene]["preset"],
         scenes.size_arg(cfg.size), list(scenes.SCENES[scene].get("render_args", [])), margin, ppv, str(path))
    rc, out, err, _, _ = run_child([PY45, "-c", code])
    if rc != 0 or not pathlib.Path(path).exists():
        raise RuntimeError(f"camera export failed: {err[-2000:]}")
