#!/usr/bin/env python3
"""bench/accuracy/report.py — docs/accuracy.md and docs/images/pareto_<scene>.png
from the accuracy sweep's results (bench/results/accuracy.json; schema: bench/accuracy/results.py).

  python bench/accuracy/report.py [--results bench/results/accuracy.json]
                                  [--docs docs/accuracy.md] [--images docs/images]

Only the text between `<!-- generated:start -->` and `<!-- generated:end -->` in
the docs file is rewritten; hand-written text outside the markers is kept.
Partial results (missing knobs, fields, scenes) give shorter tables, not errors.
Every file is written atomically (common.atomic_write). The figures come from
analysis.py, the plots from plot.py.
"""
import argparse
import json
import math
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))
from common import atomic_write, splice

from accuracy.analysis import camera_rows, id_of, knobs_in, label, point_time, scene_front
from accuracy.knobs import BY_NAME as KNOB_ROWS
from accuracy.pareto import number as num
from accuracy.plot import plot_scene

START = "<!-- generated:start -->"
END = "<!-- generated:end -->"
NEW_DOC = ("# Accuracy: the speed/accuracy trade, measured\n\n"
           "Regenerate the tables and plots with `python bench/accuracy/report.py`; "
           "text outside the generated markers is kept.\n\n")


def fmt(v, digits=3):
    """A number with `digits` significant digits, '—' when missing."""
    if v is None or isinstance(v, bool):
        return "—"
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not math.isfinite(v):
        return "—"
    return f"{v:.{digits}g}"


# ---------------------------------------------------------------- tables --

POINT_HEAD = ("| Scene | Setting | Blender | Time s (bake+render) | Render s | Bake s | Peak MiB | File MiB "
              "| RMSE | FLIP | Matched RMSE / FLIP | Field RMS / max | Pareto |\n"
              "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|")


def point_row(scene, p, front, knee_id):
    pid = id_of(p)
    where = "knee" if pid == knee_id else ("front" if pid in front else "")
    field = "—" if num(p, "field_rms") is None and num(p, "field_max") is None else \
        f"{fmt(num(p, 'field_rms'))} / {fmt(num(p, 'field_max'))}"
    matched = "—" if num(p, "matched_rmse") is None else \
        f"{fmt(num(p, 'matched_rmse'))} / {fmt(num(p, 'matched_flip'))}"
    return (f"| {scene} | {label(p)} | {p.get('blender', '—')} | {fmt(point_time(p))} | {fmt(num(p, 'render_s'))} "
            f"| {fmt(num(p, 'bake_s'))} | {fmt(num(p, 'peak_mib'))} | {fmt(num(p, 'file_mib'))} "
            f"| {fmt(num(p, 'rmse'))} | {fmt(num(p, 'flip'))} | {matched} | {field} | {where} |")


def knob_table(results, knob, fronts):
    rows = []
    for name, scene in (results.get("scenes") or {}).items():
        front, knee_id = fronts[name]
        rows += [point_row(name, p, front, knee_id) for p in scene.get("points") or [] if p.get("knob") == knob]
    return "\n".join([POINT_HEAD] + rows) if rows else ""



def camera_table(results):
    rows = camera_rows(results)
    if not rows:
        return ""
    out = ["| Scene | Camera-aware | Blender | Time s | FLIP | RMSE | Matched FLIP / RMSE "
           "| Uniform time s at equal error | Ratio (uniform / camera-aware) | How the uniform time was found |",
           "|---|---|---|--:|--:|--:|--:|--:|--:|---|"]
    for r in rows:
        c = r["cam"]
        ratio = f"×{fmt(r['ratio'], 2)}" if r["ratio"] else "—"
        m = "—" if num(c, "matched_flip") is None else f"{fmt(num(c, 'matched_flip'))} / {fmt(num(c, 'matched_rmse'))}"
        out.append(f"| {r['scene']} | {label(c)} | {c.get('blender', '—')} | {fmt(c['time_s'])} | "
                   f"{fmt(num(c, 'flip'))} | {fmt(num(c, 'rmse'))} | {m} | {fmt(r['time'])} | {ratio} | {r['how']} |")
    return "\n".join(out)


def method_section(results, images):
    m = results.get("machine") or {}
    bl = results.get("blender") or {}
    st = dict(results.get("settings") or {})
    size = st.pop("image_size", None)
    runs = st.pop("runs_per_point", None)
    out = ["## Method", ""]
    cpu = m.get("cpu_model") or "unknown CPU"
    extra = [f"{m['nproc']} cores" if m.get("nproc") else "",
             f"{fmt(m['mem_total_gib'])} GiB" if m.get("mem_total_gib") else ""]
    out.append(f"- **Machine:** {cpu}" + (f" ({', '.join(e for e in extra if e)})" if any(extra) else "") +
               (f"; load average before the sweep {', '.join(fmt(x, 2) for x in m['load_average'])}"
                if m.get("load_average") else ""))
    out.append("- **Blender:** " + (", ".join(f"{v}" for v in bl.values()) if bl else "unknown"))
    if size:
        out.append(f"- **Image:** {size[0]}×{size[1]} px")
    out.append(f"- **Runs per point:** {runs if runs is not None else 'unknown'}; times are the best run (wall "
               "seconds); *Time* = best bake + best render, the cost on the plots' x axis")
    for k, v in st.items():
        out.append(f"- **{k}:** {json.dumps(v) if not isinstance(v, str) else v}")
    out += ["",
            "**Measures.** *RMSE*: root-mean-square difference from the reference in linear radiance over R, G, B. "
            "*FLIP*: mean LDR-FLIP (NVIDIA) of the images clipped to [0, 1] and sRGB-encoded, 67 pixels per degree. "
            "*Field RMS / max*: |approx − exact| over sample points, RMS and maximum, divided by the exact field's "
            "range. *Peak MiB*: peak resident memory of the render (or bake) process; *File MiB*: the VDB's size. "
            "*Pareto*: on the scene's time–FLIP Pareto front over all knobs (*knee*: the front point farthest "
            "from the line joining its ends, in log-time/FLIP scaled to [0, 1]).", "",
            "**Reference and noise floor.** Each scene's reference is the average of two renders that differ only in "
            "the seed. *Noise RMSE / FLIP* compare the two seed renders; the reference's own error is about "
            "noise RMSE / 2 (the average of two independent renders has 1/√2 of their noise, and their difference "
            "√2 of it). Errors near that level are not resolved.", "",
            "**Matched errors.** A render at the swept 64 samples carries more noise than most knobs' bias. "
            "Every swept render uses the same seed. Cycles then draws the same random numbers, so two renders of "
            "nearly the same scene have nearly the same noise (common random numbers). *Matched RMSE / FLIP* "
            "compare a point with its baseline, the procedural render at the same render settings and seed "
            "(for the step rate: the finest step). That isolates the knob's own error: the bake's resolution, "
            "tolerance or precision, the missing octaves. It is what the camera-aware comparison uses. The "
            "sample count has no baseline, because its error is the noise itself.", "",
            "| Scene | Reference | Seeds | Render s | Noise RMSE | Reference RMSE ≈ | Noise FLIP |",
            "|---|---|---|--:|--:|--:|--:|"]
    for name, scene in (results.get("scenes") or {}).items():
        r = scene.get("reference") or {}
        ref_rmse = num(r, "reference_rmse")
        if ref_rmse is None and num(r, "noise_rmse") is not None:
            ref_rmse = num(r, "noise_rmse") / 2
        what = ", ".join(x for x in (f"{r['samples']} spp" if r.get("samples") else "",
                                     f"step rate {r['step_rate']}" if r.get("step_rate") is not None else "") if x)
        out.append(f"| {name} | {what or '—'} | {', '.join(str(s) for s in r.get('seeds') or []) or '—'} "
                   f"| {fmt(num(r, 'render_s'))} | {fmt(num(r, 'noise_rmse'))} | {fmt(ref_rmse)} "
                   f"| {fmt(num(r, 'noise_flip'))} |")
    if images:
        out += ["", "## Error against time", ""]
        for name, rel in images.items():
            out.append(f"![{name}: FLIP and RMSE against bake + render time]({rel})")
            out.append("")
    return "\n".join(out).rstrip()


def render_markdown(results, images=None):
    """The generated block (without the markers): method, tiers, camera-aware, one table per knob."""
    scenes = results.get("scenes") or {}
    fronts = {name: scene_front(s.get("points") or []) for name, s in scenes.items()}
    parts = [method_section(results, images or {})]
    knobs = knobs_in(results)
    if "tier" in knobs:
        parts.append("## Quality tiers\n\n" + knob_table(results, "tier", fronts))
    cam = camera_table(results)
    if cam:
        parts.append("## Camera-aware bake against uniform bakes\n\n"
                     "For each camera-aware bake: the cheapest uniform bake (knob *bake_resolution*, same Blender) "
                     "whose FLIP and RMSE are both ≤ the camera-aware bake's (+3 %: equal voxel sizes differ by 1–2 % "
                     "from render noise alone). These are the matched errors when every point has them, so render "
                     "noise does not decide. When there is none, the time a uniform "
                     "bake would need is estimated per measure by linear interpolation of the error against "
                     "log(time) between the two nearest uniform points of its Pareto front (extrapolation when the "
                     "camera-aware bake is better than every uniform bake), and the larger of the two times is "
                     "used; the last column says which.\n\n" + cam)
    for k in knobs:
        if k == "tier":
            continue
        table = knob_table(results, k, fronts)
        if table:
            title = KNOB_ROWS[k].title if k in KNOB_ROWS else k
            parts.append(f"## {title}\n\nKnob `{k}`.\n\n{table}")
    if not scenes:
        parts.append("_No scenes in the results._")
    return "\n\n".join(parts) + "\n"


# ----------------------------------------------------------------- files --

def write_report(results, docs, images_dir):
    """Write the plots and the docs file; returns the list of written paths."""
    docs, images_dir = Path(docs), Path(images_dir)
    written, rels = [], {}
    for name, scene in (results.get("scenes") or {}).items():
        out = images_dir / f"pareto_{name}.png"
        png = plot_scene(name, scene, results)
        if png is None:
            continue
        atomic_write(out, png)
        written.append(out)
        rels[name] = os.path.relpath(out, docs.parent)
    old = docs.read_text(encoding="utf-8") if docs.exists() else ""
    atomic_write(docs, splice(old, START, END, render_markdown(results, rels).rstrip(), new_doc=NEW_DOC))
    written.append(docs)
    return written


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--results", default=str(ROOT / "bench/results/accuracy.json"))
    ap.add_argument("--docs", default=str(ROOT / "docs/accuracy.md"))
    ap.add_argument("--images", default=str(ROOT / "docs/images"))
    a = ap.parse_args(argv)
    with open(a.results, encoding="utf-8") as f:
        results = json.load(f)
    for p in write_report(results, a.docs, a.images):
        print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
