"""Measuring one point of the accuracy sweep, and a scene's reference.

measure_point(cfg, scene, point): bake (runner.bake), render (runner.render), image
errors against the scene's reference (metrics), field error (field.py). The
result is cached in <out>/accuracy_cache/<scene>/<knob>_<setting>.json with the
specification that produced it ("key"); a later run measures only points whose
cache is missing or whose specification changed (force: all). A point whose
bake + render specification ("measure_key") equals an already measured point's
(e.g. lod on@128 = bake_resolution 128) copies its numbers ("same_as").

reference(cfg, scene): the procedural OSL render with a fine volume step and
many samples, with two seeds; their average is the reference image
(images/<scene>/ref.exr, ref.png thumbnail), their difference the noise floor.
"""
from __future__ import annotations

import hashlib
import json
import os
import pathlib
import re
import shutil
import tempfile
import time

from common import write_json

from accuracy import field, metrics, runner, scenes
from accuracy.config import ROOT


def key_of(obj):
    return hashlib.sha1(json.dumps(obj, sort_keys=True).encode()).hexdigest()[:16]


def rel(path):
    try:
        return str(pathlib.Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)



def reference(cfg, scene, blender="4.5", force=False):
    """The scene's reference (cached): dict for accuracy.json + the average image."""
    suffix = "" if blender == "4.5" else "_50"
    rs = cfg.reference_settings(scene, blender)
    spec = dict(rs, size=list(cfg.size), seeds=list(scenes.REF_SEEDS), blender=blender, source="procedural")
    if scenes.SCENES[scene].get("render_args"):
        spec["scene_args"] = list(scenes.SCENES[scene]["render_args"])
    cache = cfg.cache / scene / f"reference{suffix}.json"
    img_dir = cfg.images / scene
    avg_path = img_dir / f"ref{suffix}.exr"
    if cache.exists() and not force:
        c = json.loads(cache.read_text())
        if c.get("key") == key_of(spec) and avg_path.exists():
            return c, metrics.load_exr(avg_path)
    runner.log(f"[{scene}] reference (Blender {blender}): {spec}")
    imgs, times, peaks = [], [], []
    load = [round(x, 2) for x in os.getloadavg()]
    for seed in scenes.REF_SEEDS:
        out = img_dir / f"ref{suffix}_seed{seed}.exr"
        r = runner.render(scene, dict(spec, seed=seed), out, blender, 1)
        imgs.append(metrics.load_exr(out))
        times.append(r["render_s"])
        peaks.append(r["peak_mib"])
        runner.log(f"[{scene}] reference seed {seed}: {r['render_s']:.1f} s")
        cfg.versions[blender] = r["version"]
    avg = (imgs[0] + imgs[1]) / 2
    metrics.write_exr(avg_path, avg)
    metrics.write_png(img_dir / f"ref{suffix}.png", avg)
    nf = metrics.noise_floor(imgs[0], imgs[1])
    c = {"key": key_of(spec), "spec": spec, "samples": rs["samples"], "step_rate": rs.get("step_rate"),
         "volume_biased": rs.get("volume_biased"), "seeds": list(scenes.REF_SEEDS),
         "noise_rmse": nf["noise_rmse"], "noise_flip": nf["noise_flip"],
         "reference_rmse": nf.get("reference_rmse"), "render_s": max(times), "render_s_all": times,
         "peak_mib": max(peaks), "image": rel(avg_path), "blender": blender, "version": cfg.versions[blender],
         "mean_radiance": float(avg.mean()), "load_before": load}
    write_json(cache, c)
    runner.log(f"[{scene}] reference: noise rmse {c['noise_rmse']:.4f} flip {c['noise_flip']:.4f}")
    return c, avg


# ------------------------------------------------------------------ point --
SAME_AS_KEYS = ("render_s", "render_s_all", "peak_mib", "rmse", "flip", "image", "bake_s", "bake_s_all",
                "bake_peak_mib", "file_mib", "bake_cmd", "camera_voxel", "visible_tiles", "total_tiles")


def safe(s):
    return re.sub(r"[^A-Za-z0-9@=.+-]", "_", s)


def point_spec(scene, pt):
    """What the point's figures depend on: its cache key is key_of(this)."""
    spec = {k: pt[k] for k in ("render", "bake", "field", "blender")}
    spec["preset"] = scenes.SCENES[scene]["preset"]
    if scenes.SCENES[scene].get("render_args"):
        spec["scene_args"] = list(scenes.SCENES[scene]["render_args"])
    if pt["field"] and pt["field"].get("kind", "").startswith("bake"):
        spec["field_footprint"] = field.has_footprint()
    return spec


def measured_before(cfg, scene, cache, mkey, ref):
    """The figures of another cached point with the same bake + render (e.g. lod on@128 =
    bake_resolution 128) against the same reference, with same_as; None if there is none."""
    for other in sorted((cfg.cache / scene).glob("*.json")):
        if other == cache or other.name.startswith("reference"):
            continue
        o = json.loads(other.read_text())
        if o.get("measure_key") == mkey and o.get("reference_key") == ref["key"] and "rmse" in o:
            res = {k: o[k] for k in SAME_AS_KEYS if k in o}
            res["same_as"] = other.stem
            return res
    return None


def bake_and_render(cfg, scene, pt, name, ref_img):
    """Bake (if the point has one), render, image errors against the reference."""
    res = {"load_before": [round(x, 2) for x in os.getloadavg()]}
    work = pathlib.Path(tempfile.mkdtemp(prefix="cloudgen-acc-"))
    try:
        vdb = None
        if pt["bake"]:
            vdb = work / "cloud.vdb"
            res.update(runner.bake(cfg, scene, pt["bake"], vdb, work))
        if pt["render"]:
            out = cfg.images / scene / f"{name}.exr"
            r = runner.render(scene, pt["render"], out, pt["blender"], cfg.runs, vdb=vdb, workdir=work)
            cfg.versions[pt["blender"]] = r.pop("version")
            img = metrics.load_exr(out)
            res.update(r, image=rel(out), rmse=metrics.image_rmse(img, ref_img),
                       flip=metrics.image_flip(img, ref_img))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return res


def field_figures(cfg, scene, pt, res):
    """Adds the point's field error (and for a preview its slice time) to `res`."""
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
        res.update(field.preview_error(params, f["size"], f["exact_size"] if not cfg.quick else 256))
        res["render_s"] = None
    res.setdefault("field_rms", None)
    res.setdefault("field_max", None)


def measure_point(cfg, scene, pt, force):
    """(cached result, whether it was measured now) of one point."""
    name = f"{pt['knob']}_{safe(pt['setting'])}" + (f"_{pt['variant']}" if pt.get("variant") else "")
    cache = cfg.cache / scene / f"{name}.json"
    spec = point_spec(scene, pt)
    mkey = key_of({k: spec[k] for k in ("render", "bake", "blender", "preset", "scene_args") if k in spec})
    key = key_of(spec)
    if cache.exists() and not force:
        c = json.loads(cache.read_text())
        if c.get("key") == key:
            return c, False
    ref, ref_img = reference(cfg, scene, pt["blender"]) if pt["render"] else (None, None)
    res = measured_before(cfg, scene, cache, mkey, ref) if not force and pt["render"] else None
    runner.log(f"[{scene}] {pt['knob']} {pt['setting']}{' ' + pt['variant'] if pt.get('variant') else ''}"
               + (f" (= {res['same_as']})" if res else ""))
    if res is None:
        res = bake_and_render(cfg, scene, pt, name, ref_img)
    field_figures(cfg, scene, pt, res)
    res["time_s"] = (res.get("slice_s") if pt["knob"] == "preview_resolution"
                     else res.get("bake_s", 0.0) + res["render_s"])
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
    runner.log(msg)
    return c, True
