#!/usr/bin/env python3
"""The accuracy sweep of issue 6: error against time for each speed/accuracy knob.

  .venv/bin/python bench/accuracy/sweep.py [--quick] [--scenes a,b] [--knobs x,y] [--force]
                                           [--runs N] [--out DIR]

For each scene (bench/accuracy/scenes.py) a reference image (procedural OSL,
fine volume step, many samples, two seeds averaged), then for every knob in
KNOBS, each setting alone with the others at the base settings: bake (the
`cloudgen` CLI, best of 3, peak RSS through os.wait4, VDB size), render in a
subprocess (render_job.py, best of --runs, peak RSS through os.wait4), image
error against the reference (metrics.image_rmse / image_flip) and field error
(field.py). Every point is cached in <out>/accuracy_cache/<scene>/<knob>_<setting>.json
with the specification that produced it; a re-run measures only points whose
cache is missing or whose specification changed (--force: all of them). A
point whose bake + render specification equals an already measured point's
(e.g. lod on@128 = bake_resolution 128) copies its numbers ("same_as").
<out>/accuracy.json (schema: /tmp/issue6/INTERFACES.md) is rewritten from the
whole cache after every point, so an interrupted run leaves valid results.
Renders go to <out>/images/<scene>/ (EXR, not committed; ref.png thumbnails are).

--quick: 32x24 pixels, few samples, one run, two settings per knob, into a
temporary directory (a smoke test of a few minutes).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

import field  # noqa: E402
import scenes  # noqa: E402
from common import machine_info, write_json  # noqa: E402

PY45 = ROOT / ".venv/bin/python"
PY50 = ROOT / ".venv-blender5/bin/python"
CLOUDGEN = ROOT / "build/bin/cloudgen"
RENDER_JOB = HERE / "render_job.py"
BAKE_RUNS = 3
QUICK = False


# ------------------------------------------------------------------ knobs --
# One row per knob: its settings (text), the settings in --quick, the scenes it
# runs on (None = all) and how a setting becomes a point (make_point below).
KNOBS = [
    {"knob": "procedural", "settings": ["osl"], "quick": ["osl"]},
    {"knob": "bake_resolution", "settings": ["64", "128", "256", "512"], "quick": ["32", "64"]},
    {"knob": "samples", "settings": ["4", "16", "64", "256"], "quick": ["2", "8"]},
    {"knob": "step_rate", "settings": ["2", "1", "0.5", "0.25", "0.177"], "quick": ["2", "0.5"]},
    {"knob": "bake_half", "settings": ["128", "256"], "quick": ["64"]},
    {"knob": "lod", "settings": ["on@128", "off@128", "on@256", "off@256"], "quick": ["on@64", "off@64"]},
    {"knob": "tolerance", "settings": ["0", "0.01", "0.05", "0.1", "0.3", "1"], "quick": ["0", "0.1"]},
    {"knob": "skip_empty", "settings": ["on@128", "off@128"], "quick": ["off@64"]},
    {"knob": "noise_detail", "settings": ["1", "2", "3", "4", "preset"], "quick": ["2", "preset"]},
    {"knob": "preview_resolution", "settings": ["64", "128", "256", "512", "1024"], "quick": ["64", "256"]},
    {"knob": "tier", "settings": "tiers", "quick": ["draft"]},
    {"knob": "camera_aware", "settings": ["ppv=1", "ppv=2", "ppv=4"], "quick": ["ppv=2"],
     # the margin around the view (margin=cli: the CLI's optical-depth default), where it can matter
     "extra_settings": {"cumulus_closeup": ["ppv=1,margin=0", "ppv=1,margin=cli"]}},
    {"knob": "volume_biased", "settings": ["biased", "unbiased"], "quick": ["biased", "unbiased"],
     "scenes": ["cumulus"]},
]
TOLERANCE_AT, SKIP_AT = 128, 128
VDB_MATERIAL = 2  # render_cloud.py --vdb shader version (1 squared the density): part of the cache key
QUICK_AT = 64


def cli_help():
    try:
        return subprocess.run([str(CLOUDGEN), "bake", "--help"], capture_output=True, text=True).stdout
    except OSError:
        return ""


def tiers():
    import cloudgen_native as cn
    if hasattr(cn, "tiers"):
        return cn.tiers()
    path = ROOT / "native/presets/tiers.json"
    return json.loads(path.read_text()) if path.exists() else {}


def knob_settings(row, preset_values):
    s = row["quick"] if QUICK else row["settings"]
    if s == "tiers":
        s = list(tiers())
    out = []
    for x in s:
        if x == "preset":  # noise_detail: the preset's own value
            d = preset_values["noise_detail"]
            x = f"{d:g}"
        if x not in out:
            out.append(x)
    return out


def bake_spec(resolution, half=False, lod=True, tolerance=0.0, skip=True, **extra):
    return dict({"resolution": int(resolution), "half": bool(half), "lod": bool(lod),
                 "tolerance": float(tolerance), "skip": bool(skip)}, **extra)


def make_points(knob, setting, scene, cfg):
    """The point(s) of one knob setting: dicts with knob, setting, label, blender,
    render (spec or None), bake (spec or None), field (spec or None)."""
    base = cfg["base"]
    render = {"source": "procedural", "samples": base["samples"], "step_rate": base["step_rate"],
              "seed": scenes.SWEEP_SEED, "size": list(cfg["size"])}
    P = lambda label, **kw: dict({"knob": knob, "setting": setting, "label": label,  # noqa: E731
                                  "blender": "4.5", "render": dict(render), "bake": None, "field": None}, **kw)
    vdb = dict(render, source="vdb", vdb_material=VDB_MATERIAL)
    if knob == "procedural":
        return [P(f"Procedural OSL ({base['samples']} spp)")]
    if knob == "bake_resolution":
        b = bake_spec(setting)
        return [P(f"VDB {setting}³", render=vdb, bake=b, field={"kind": "bake", **b})]
    if knob == "bake_half":
        b = bake_spec(setting, half=True)
        return [P(f"VDB {setting}³ half", render=vdb, bake=b, field={"kind": "bake", **b})]
    if knob == "lod":
        mode, res = setting.split("@")
        b = bake_spec(res, lod=mode == "on")
        return [P(f"VDB {res}³ LOD {mode}", render=vdb, bake=b, field={"kind": "bake", **b})]
    if knob == "tolerance":
        res = QUICK_AT if QUICK else TOLERANCE_AT
        b = bake_spec(res, tolerance=float(setting))
        return [P(f"VDB {res}³ tolerance {setting}", render=vdb, bake=b, field={"kind": "bake", **b})]
    if knob == "skip_empty":
        mode, res = setting.split("@")
        b = bake_spec(res, skip=mode == "on")
        return [P(f"VDB {res}³ skip empty {mode}", render=vdb, bake=b, field={"kind": "bake", **b})]
    if knob == "noise_detail":
        r = dict(render, params={"noise_detail": float(setting)})
        return [P(f"Noise detail {setting} (procedural)", render=r,
                  field={"kind": "detail", "detail": float(setting)})]
    if knob == "step_rate":
        return [P(f"Step rate ×{setting}", render=dict(render, step_rate=float(setting)))]
    if knob == "samples":
        return [P(f"{setting} spp", render=dict(render, samples=int(setting)))]
    if knob == "volume_biased":
        r = dict(render, volume_biased="on" if setting == "biased" else "off")
        return [P(f"Blender 5.0 {setting}", blender="5.0", render=r)]
    if knob == "preview_resolution":
        return [P(f"Preview {setting} px", render=None,
                  field={"kind": "preview", "size": int(setting), "exact_size": 1024})]
    if knob == "tier":
        t = tiers()[setting]
        tb, tr = t["bake"], t["render"]
        b = bake_spec(tb["resolution"], half=tb.get("half", False), lod=tb.get("lod", True),
                      tolerance=tb.get("tolerance", 0.0), quality=setting)
        r = dict(render, samples=int(tr["samples"]), step_rate=float(tr["step_rate"]))
        name = t.get("label", setting)
        return [P(f"{name} (VDB {tb['resolution']}³, {tr['samples']} spp)",
                  render=dict(r, source="vdb", vdb_material=VDB_MATERIAL),
                  bake=b, field={"kind": "bake", **b}, variant="vdb"),
                P(f"{name} (procedural, {tr['samples']} spp)", render=r, variant="procedural")]
    if knob == "camera_aware":
        kv = dict(item.split("=") for item in setting.split(","))
        margin = 0.5 if "margin" not in kv else (None if kv["margin"] == "cli" else float(kv["margin"]))
        b = {"camera": True, "pixels_per_voxel": float(kv["ppv"]), "margin": margin, "lod": True, "half": False,
             "tolerance": 0.0, "skip": True}
        text = "default" if margin is None else f"{margin:g}"
        return [P(f"Camera-aware VDB, {kv['ppv']} px/voxel, margin {text}", render=vdb, bake=b,
                  field={"kind": "bake_camera"})]
    raise ValueError(knob)


def available(knob):
    if knob == "camera_aware":
        return "--camera" in cli_help()
    if knob == "tier":
        return bool(tiers())
    if knob == "volume_biased":
        return PY50.exists()
    return True


# ---------------------------------------------------------------- helpers --
def key_of(obj):
    return hashlib.sha1(json.dumps(obj, sort_keys=True).encode()).hexdigest()[:16]


def rel(path):
    try:
        return str(pathlib.Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


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


def log(msg):
    print(time.strftime("%H:%M:%S"), msg, flush=True)


# ---------------------------------------------------------------- renders --
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


def bake(scene, spec, output, workdir):
    cmd = [CLOUDGEN, "bake", "--quiet", "--preset", scenes.SCENES[scene]["preset"], "--output", output]
    if spec.get("camera"):
        cam = pathlib.Path(workdir) / "camera.json"
        export_camera(scene, cam, spec["pixels_per_voxel"], spec.get("margin"))
        cmd += ["--camera", cam]
        if spec.get("resolution"):
            cmd += ["--resolution", spec["resolution"]]
    elif spec.get("quality") and "--quality" in cli_help():
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
    times, peaks, out = [], [], ""
    for _ in range(BAKE_RUNS):
        rc, out, err, wall, peak = run_child(cmd)
        if rc != 0:
            raise RuntimeError(f"bake failed (exit {rc}): {' '.join(map(str, cmd))}\n{out[-1000:]}{err[-1000:]}")
        times.append(wall)
        peaks.append(peak)
    res = {"bake_s": min(times), "bake_s_all": times, "bake_peak_mib": max(peaks),
           "file_mib": os.path.getsize(output) / 2 ** 20, "bake_cmd": " ".join(map(str, cmd[1:])).replace(
               str(workdir) + "/", "")}
    m = re.search(r"camera: voxel ([0-9.eE+-]+), (\d+) visible tiles of (\d+)", out)
    if m:
        res.update(camera_voxel=float(m.group(1)), visible_tiles=int(m.group(2)), total_tiles=int(m.group(3)))
    return res


def export_camera(scene, path, ppv, margin):
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
         scenes.size_arg(CFG["size"]), list(scenes.SCENES[scene].get("render_args", [])), margin, ppv, str(path))
    rc, out, err, _, _ = run_child([PY45, "-c", code])
    if rc != 0 or not pathlib.Path(path).exists():
        raise RuntimeError(f"camera export failed: {err[-2000:]}")


# -------------------------------------------------------------- reference --
def reference(scene, blender="4.5", force=False):
    """The scene's reference (cached): dict for accuracy.json + the average image."""
    import metrics
    suffix = "" if blender == "4.5" else "_50"
    if blender == "4.5":
        rs = CFG["reference"] if QUICK else scenes.REFERENCE[scene]
    else:
        rs = scenes.QUICK_REFERENCE_50 if QUICK else scenes.REFERENCE_50[scene]
    spec = dict(rs, size=list(CFG["size"]), seeds=list(scenes.REF_SEEDS), blender=blender, source="procedural")
    if scenes.SCENES[scene].get("render_args"):
        spec["scene_args"] = list(scenes.SCENES[scene]["render_args"])
    cache = CFG["cache"] / scene / f"reference{suffix}.json"
    img_dir = CFG["images"] / scene
    avg_path = img_dir / f"ref{suffix}.exr"
    if cache.exists() and not force:
        c = json.loads(cache.read_text())
        if c.get("key") == key_of(spec) and avg_path.exists():
            return c, metrics.load_exr(avg_path)
    log(f"[{scene}] reference (Blender {blender}): {spec}")
    imgs, times, peaks = [], [], []
    load = [round(x, 2) for x in os.getloadavg()]
    for seed in scenes.REF_SEEDS:
        out = img_dir / f"ref{suffix}_seed{seed}.exr"
        r = render(scene, dict(spec, seed=seed), out, blender, 1)
        imgs.append(metrics.load_exr(out))
        times.append(r["render_s"])
        peaks.append(r["peak_mib"])
        log(f"[{scene}] reference seed {seed}: {r['render_s']:.1f} s")
        CFG["versions"][blender] = r["version"]
    avg = (imgs[0] + imgs[1]) / 2
    metrics.write_exr(avg_path, avg)
    metrics.write_png(img_dir / f"ref{suffix}.png", avg)
    nf = metrics.noise_floor(imgs[0], imgs[1])
    c = {"key": key_of(spec), "spec": spec, "samples": rs["samples"], "step_rate": rs.get("step_rate"),
         "volume_biased": rs.get("volume_biased"), "seeds": list(scenes.REF_SEEDS),
         "noise_rmse": nf["noise_rmse"], "noise_flip": nf["noise_flip"],
         "reference_rmse": nf.get("reference_rmse"), "render_s": max(times), "render_s_all": times,
         "peak_mib": max(peaks), "image": rel(avg_path), "blender": blender, "version": CFG["versions"][blender],
         "mean_radiance": float(avg.mean()), "load_before": load}
    write_json(cache, c)
    log(f"[{scene}] reference: noise rmse {c['noise_rmse']:.4f} flip {c['noise_flip']:.4f}")
    return c, avg


# ------------------------------------------------------------------ point --
def safe(s):
    return re.sub(r"[^A-Za-z0-9@=.+-]", "_", s)


def measure_point(scene, pt, force):
    import metrics
    name = f"{pt['knob']}_{safe(pt['setting'])}" + (f"_{pt['variant']}" if pt.get("variant") else "")
    cache = CFG["cache"] / scene / f"{name}.json"
    spec = {k: pt[k] for k in ("render", "bake", "field", "blender")}
    spec["preset"] = scenes.SCENES[scene]["preset"]
    if scenes.SCENES[scene].get("render_args"):
        spec["scene_args"] = list(scenes.SCENES[scene]["render_args"])
    if pt["field"] and pt["field"].get("kind", "").startswith("bake"):
        spec["field_footprint"] = field.has_footprint()
    mkey = key_of({k: spec[k] for k in ("render", "bake", "blender", "preset", "scene_args") if k in spec})
    key = key_of(spec)
    if cache.exists() and not force:
        c = json.loads(cache.read_text())
        if c.get("key") == key:
            return c, False
    ref = None
    if pt["render"]:
        ref, ref_img = reference(scene, pt["blender"])
    res = None
    # the same bake + render measured under another knob (e.g. lod on@128 = bake_resolution 128)?
    if not force and pt["render"]:
        for other in sorted((CFG["cache"] / scene).glob("*.json")):
            if other == cache or other.name.startswith("reference"):
                continue
            o = json.loads(other.read_text())
            if o.get("measure_key") == mkey and o.get("reference_key") == ref["key"] and "rmse" in o:
                res = {k: o[k] for k in ("render_s", "render_s_all", "peak_mib", "rmse", "flip", "image",
                                         "bake_s", "bake_s_all", "bake_peak_mib", "file_mib", "bake_cmd",
                                         "camera_voxel", "visible_tiles", "total_tiles") if k in o}
                res["same_as"] = other.stem
                break
    log(f"[{scene}] {pt['knob']} {pt['setting']}{' ' + pt['variant'] if pt.get('variant') else ''}"
        + (f" (= {res['same_as']})" if res else ""))
    if res is None:
        res = {"load_before": [round(x, 2) for x in os.getloadavg()]}
        work = pathlib.Path(tempfile.mkdtemp(prefix="cloudgen-acc-"))
        try:
            vdb = None
            if pt["bake"]:
                vdb = work / "cloud.vdb"
                res.update(bake(scene, pt["bake"], vdb, work))
            if pt["render"]:
                out = CFG["images"] / scene / f"{name}.exr"
                r = render(scene, pt["render"], out, pt["blender"], CFG["runs"], vdb=vdb, workdir=work)
                CFG["versions"][pt["blender"]] = r.pop("version")
                img = metrics.load_exr(out)
                res.update(r, image=rel(out), rmse=metrics.image_rmse(img, ref_img),
                           flip=metrics.image_flip(img, ref_img))
        finally:
            shutil.rmtree(work, ignore_errors=True)
    f = pt["field"]
    params = {"preset": scenes.SCENES[scene]["preset"]}
    if f and f["kind"] == "bake":
        res.update(field.bake_field_error(params, f["resolution"], f["lod"], f["tolerance"], f["half"]))
    elif f and f["kind"] == "bake_camera" and res.get("camera_voxel"):
        res.update(field.bake_field_error(params, lod=True, voxel=res["camera_voxel"]))
        res["field_note"] = "grid of the camera voxel over the whole box (tiles outside the view not culled)"
    elif f and f["kind"] == "detail":
        res.update(field.detail_field_error(params, f["detail"]))
    elif f and f["kind"] == "preview":
        res.update(field.preview_error(params, f["size"], f["exact_size"] if not QUICK else 256))
        res["render_s"] = None
    res.setdefault("field_rms", None)
    res.setdefault("field_max", None)
    bake_s = res.get("bake_s", 0.0)
    res["time_s"] = (res.get("slice_s") if pt["knob"] == "preview_resolution"
                     else bake_s + res["render_s"])
    c = dict({"knob": pt["knob"], "setting": pt["setting"], "label": pt["label"], "blender": pt["blender"]},
             **({"variant": pt["variant"]} if pt.get("variant") else {}),
             key=key, measure_key=mkey, reference_key=ref["key"] if ref else None, spec=spec,
             measured_at=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), **res)
    write_json(cache, c)
    msg = f"[{scene}]   time {c['time_s']:.3f} s"
    if c.get("bake_s"):
        msg += f" (bake {c['bake_s']:.2f} s, {c['file_mib']:.2f} MiB)"
    if c.get("rmse") is not None:
        msg += f" rmse {c['rmse']:.4f} flip {c['flip']:.4f} peak {c['peak_mib']:.0f} MiB"
    if c.get("field_rms") is not None:
        msg += f" field rms {c['field_rms']:.5f} max {c['field_max']:.4f}"
    log(msg)
    return c, True


# ---------------------------------------------------------------- results --
POINT_KEYS = ["knob", "setting", "label", "blender", "variant", "render_s", "render_s_all", "bake_s",
              "bake_s_all", "time_s", "peak_mib", "bake_peak_mib", "file_mib", "rmse", "flip", "field_rms",
              "field_max", "field_range", "same_as", "image", "bake_cmd", "field_lod", "voxel", "grid", "camera_voxel",
              "visible_tiles", "total_tiles", "load_before", "slice_s", "slice_s_all", "slice_size", "field_note",
              "measured_at", "matched_rmse", "matched_flip", "matched_to"]


def write_results():
    order = {r["knob"]: i for i, r in enumerate(KNOBS)}
    out = {"machine": CFG["machine"], "blender": {}, "settings": {
        "image_size": list(CFG["size"]), "runs_per_point": CFG["runs"], "bake_runs": BAKE_RUNS,
        "base_render": dict(CFG["base"]), "sweep_seed": scenes.SWEEP_SEED,
        "quick": QUICK,
        "notes": [
            "step_rate = scene.cycles.volume_step_rate (Render > Volume step rate), a factor on every "
            "material's step rate: procedural material = the preset's (cumulus/stratocumulus 0.2, cirrus 0.5) "
            "x 1/10 of the box's mean side; VDB material 1 x the voxel size (as the add-on's bake).",
            "Base render of every swept point: render_cloud.py's defaults (64 spp, step rate 1), seed 0; "
            "Cycles CPU, 2 threads, denoising off. Procedural renders use OSL; VDB renders use SVM "
            "(no script nodes needed).",
            "render_s: wall time of bpy.ops.render.render only (no bpy import, no scene build), best of "
            "runs_per_point; bake_s: wall time of `cloudgen bake --quiet` (process start and VDB write "
            "included), best of bake_runs; peak_mib: peak RSS of the render process (os.wait4); "
            "bake_peak_mib: of the bake process.",
            "Field errors: 20000 uniform points in the box (fixed seed); a bake's value is the trilinear "
            "interpolation of its voxel-centre values (density with footprint = voxel when LOD is on).",
            "volume_biased points are Blender 5.0 renders compared with a Blender 5.0 reference "
            "(unbiased null-scattering integrator, reference_50).",
            "Points with same_as copy the measurement of a point with the identical bake and render.",
        ]}, "scenes": {}}
    for scene in CFG["all_scenes"]:
        d = CFG["cache"] / scene
        if not d.exists():
            continue
        entry = {"preset": scenes.SCENES[scene]["preset"], "description": scenes.SCENES[scene]["description"]}
        for blender, fname in (("4.5", "reference.json"), ("5.0", "reference_50.json")):
            if (d / fname).exists():
                r = json.loads((d / fname).read_text())
                ref = {k: r.get(k) for k in ("samples", "step_rate", "volume_biased", "seeds", "noise_rmse",
                                             "noise_flip", "reference_rmse", "render_s", "render_s_all",
                                             "peak_mib", "image", "mean_radiance", "load_before")}
                ref["render_s"] = min(r.get("render_s_all") or [r.get("render_s")])  # best, as for points
                entry["reference" if blender == "4.5" else "reference_50"] = ref
                out["blender"][blender] = r.get("version")
        pts = []
        for f in sorted(d.glob("*.json")):
            if f.name.startswith("reference"):
                continue
            c = json.loads(f.read_text())
            pts.append({k: c[k] for k in POINT_KEYS if k in c})
        pts.sort(key=lambda p: (order.get(p["knob"], 99), _num(p["setting"]), p.get("variant", "")))
        entry["points"] = pts
        out["scenes"][scene] = entry
    out["blender"].update({k: v for k, v in CFG["versions"].items() if v})
    write_json(CFG["results"], out)


def _num(s):
    m = re.search(r"[0-9.]+", str(s))
    try:
        v = float(m.group(0)) if m else 0.0
    except ValueError:
        v = 0.0
    return (str(s).split("@")[0] if "@" in str(s) else "", v)


CFG = {}


def main(argv=None):
    global QUICK
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--scenes", default=",".join(s for s, d in scenes.SCENES.items() if not d.get("extra")))
    ap.add_argument("--knobs", default=",".join(r["knob"] for r in KNOBS))
    ap.add_argument("--force", action="store_true", help="re-measure cached points and references")
    ap.add_argument("--runs", type=int, default=None, help="renders per point (default 2, --quick 1)")
    ap.add_argument("--out", default=None, help="results directory (default bench/results; --quick: a temp dir)")
    ap.add_argument("--results-only", action="store_true",
                    help="only rewrite accuracy.json from the cache (e.g. after matched.py)")
    a = ap.parse_args(argv)
    QUICK = a.quick
    out = pathlib.Path(a.out) if a.out else (pathlib.Path(tempfile.mkdtemp(prefix="cloudgen-accuracy-"))
                                              if QUICK else ROOT / "bench/results")
    CFG.update(size=scenes.QUICK_IMAGE_SIZE if QUICK else scenes.IMAGE_SIZE,
               base=scenes.QUICK_BASE if QUICK else scenes.BASE, reference=scenes.QUICK_REFERENCE,
               runs=a.runs or (1 if QUICK else 2), cache=out / "accuracy_cache", images=out / "images",
               results=out / "accuracy.json", machine=machine_info(), versions={},
               all_scenes=list(scenes.SCENES))
    want_scenes = [s for s in a.scenes.split(",") if s]
    want_knobs = [k for k in a.knobs.split(",") if k]
    for s in want_scenes:
        if s not in scenes.SCENES:
            raise SystemExit(f"sweep: unknown scene {s!r}; known: {list(scenes.SCENES)}")
    for k in want_knobs:
        if k not in {r["knob"] for r in KNOBS}:
            raise SystemExit(f"sweep: unknown knob {k!r}; known: {[r['knob'] for r in KNOBS]}")
    log(f"accuracy sweep into {out} (quick={QUICK}, scenes {want_scenes}, knobs {want_knobs})")
    if a.results_only:
        write_results()
        return 0
    import cloudgen_native as cn
    t_start = time.time()
    for s in want_scenes:  # the references first: every image error needs them
        reference(s, "4.5", force=a.force)
        write_results()
    failures = []
    for row in KNOBS:
        if row["knob"] not in want_knobs:
            continue
        if not available(row["knob"]):
            log(f"skip {row['knob']}: not available yet")
            continue
        for s in want_scenes:
            if row.get("scenes") and s not in row["scenes"]:
                continue
            if scenes.SCENES[s].get("knobs") and row["knob"] not in scenes.SCENES[s]["knobs"]:
                continue
            values = cn.presets()[scenes.SCENES[s]["preset"]]["params"]
            settings = knob_settings(row, dict(cn.defaults(), **values))
            settings = list(settings) + ([] if QUICK else row.get("extra_settings", {}).get(s, []))
            for setting in settings:
                for pt in make_points(row["knob"], setting, s, CFG):
                    try:
                        measure_point(s, pt, a.force)
                    except Exception as exc:  # keep going: one failed point must not stop the sweep
                        failures.append(f"{s} {pt['knob']} {setting}: {exc}")
                        log(f"[{s}] FAILED {pt['knob']} {setting}: {exc}")
                    write_results()
    write_results()
    log(f"done in {time.time() - t_start:.0f} s; results {CFG['results']}")
    for f in failures:
        log("FAILED " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
