#!/usr/bin/env python3
"""bench/accuracy/report.py — docs/accuracy.md and docs/images/pareto_<scene>.png
from the accuracy sweep's results (schema: bench/results/accuracy.json, issue 6).

  python bench/accuracy/report.py [--results bench/results/accuracy.json]
                                  [--docs docs/accuracy.md] [--images docs/images]

Only the text between `<!-- generated:start -->` and `<!-- generated:end -->` in
the docs file is rewritten; hand-written text outside the markers is kept.
Partial results (missing knobs, fields, scenes) give shorter tables, not errors.
Every file is written atomically (temporary file + os.replace).
"""
import argparse
import json
import math
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))
from accuracy.pareto import knee, pareto_front  # noqa: E402
from accuracy.pareto import number as num

START = "<!-- generated:start -->"
END = "<!-- generated:end -->"
KNOB_ORDER = ["tier", "procedural", "bake_resolution", "bake_half", "noise_detail", "lod", "tolerance",
              "skip_empty", "camera_aware", "step_rate", "samples", "volume_biased", "preview_resolution"]
KNOB_TITLES = {
    "tier": "Quality tiers (Draft / Preview / Final)",
    "procedural": "Procedural (OSL at render time, no bake)",
    "bake_resolution": "Bake resolution (uniform VDB)",
    "bake_half": "Half-float VDB",
    "noise_detail": "Noise detail (octaves)",
    "lod": "Level of detail (octaves capped at the voxel size)",
    "tolerance": "Bake tolerance",
    "skip_empty": "Skipping empty tiles",
    "camera_aware": "Camera-aware bake",
    "step_rate": "Volume step rate",
    "samples": "Samples per pixel",
    "volume_biased": "Biased volume rendering (Blender 5.0)",
    "preview_resolution": "Preview slice resolution (field error only; time = slice time)",
}


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


def point_time(p):
    """time_s, or bake_s + render_s when time_s is absent."""
    t = num(p, "time_s")
    if t is None and num(p, "render_s") is not None:
        t = num(p, "render_s") + (num(p, "bake_s") or 0.0)
    return t


def with_time(points):
    return [dict(p, time_s=point_time(p)) for p in points]


def label(p):
    return str(p.get("label") or f"{p.get('knob', '?')} {p.get('setting', '')}".strip())


def knobs_in(results):
    seen = []
    for scene in (results.get("scenes") or {}).values():
        for p in scene.get("points") or []:
            k = p.get("knob", "?")
            if k not in seen:
                seen.append(k)
    return sorted(seen, key=lambda k: (KNOB_ORDER.index(k) if k in KNOB_ORDER else len(KNOB_ORDER), k))


def scene_front(points):
    """(front ids, knee id) of a scene over all its points: time_s vs FLIP, time > 0."""
    pts = [p for p in with_time(points) if (p["time_s"] or 0) > 0]
    front = pareto_front(pts, "time_s", "flip")
    k = knee(front, "time_s", "flip")
    return {id_of(p) for p in front}, (id_of(k) if k else None)


def id_of(p):
    return (p.get("knob"), str(p.get("setting")), str(p.get("blender")), p.get("label"))


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


def log_interp(a, b, metric, target):
    """log-linear time at which the straight line through a and b (log10 time vs
    metric) reaches `target`; None if the line is flat or rises."""
    ya, yb = num(a, metric), num(b, metric)
    ta, tb = math.log10(a["time_s"]), math.log10(b["time_s"])
    if ya is None or yb is None or ya == yb or (yb - ya) * (tb - ta) >= 0:
        return None
    return 10 ** (ta + (target - ya) * (tb - ta) / (yb - ya))


def time_at_error(uniform, metric, target):
    """(time, how) for the uniform bakes to reach metric <= target: the cheapest
    measured point when there is one (interpolated in log time from the previous,
    worse point on the front when that brackets the target), else extrapolated
    from the two most accurate front points. (None, reason) when impossible."""
    front = pareto_front([p for p in uniform if (p["time_s"] or 0) > 0], "time_s", metric)
    if not front:
        return None, f"no uniform {metric}"
    for i, p in enumerate(front):
        if num(p, metric) <= target:
            if i == 0:
                return p["time_s"], f"measured ({label(p)})"
            t = log_interp(front[i - 1], p, metric, target)
            return t, f"interpolated in log time between {label(front[i - 1])} and {label(p)}"
    if len(front) < 2:
        return None, f"only {label(front[0])}, {metric} above target"
    t = log_interp(front[-2], front[-1], metric, target)
    if t is None:
        return None, "uniform error does not fall with time"
    return t, f"extrapolated in log time beyond {label(front[-1])}"


# "Equal error" allows this relative margin: two bakes of the same voxel size differ
# by ~1-2 % in their matched errors from render noise alone (measured: the
# cumulus camera-aware bake and the uniform 128³ bake have the same voxel).
EQUAL_ERROR = 0.03


def camera_rows(results):
    """One row per camera-aware point: the uniform bake at equal error and the time ratio."""
    rows = []
    for name, scene in (results.get("scenes") or {}).items():
        pts = with_time(scene.get("points") or [])
        cams = [p for p in pts if p.get("knob") == "camera_aware"]
        for cam in cams:
            same = [p for p in pts if p.get("knob") == "bake_resolution" and p.get("blender") == cam.get("blender")]
            uniform = same or [p for p in pts if p.get("knob") == "bake_resolution"]
            uniform = [p for p in uniform if p["time_s"] is not None]
            # Matched errors (same seed as the procedural baseline) isolate the bake's
            # own error from render noise; use them when every point has them.
            matched = all(num(p, "matched_flip") is not None for p in [cam] + uniform)
            choice = ("matched_flip", "matched_rmse") if matched else ("flip", "rmse")
            metrics = [m for m in choice if num(cam, m) is not None]
            t_cam = cam["time_s"]
            row = {"scene": name, "cam": cam, "time": None, "how": "", "ratio": None}
            if not metrics or not uniform or not t_cam:
                row["how"] = "no uniform bakes / errors to compare" if not uniform or not metrics else "no time"
                rows.append(row)
                continue
            ok = [p for p in uniform
                  if all(num(p, m) is not None and num(p, m) <= num(cam, m) * (1 + EQUAL_ERROR) for m in metrics)]
            if ok:
                best = min(ok, key=lambda p: p["time_s"])
                row.update(time=best["time_s"], how=f"measured: {label(best)} ({' and '.join(metrics)} ≤)")
            else:
                est = [(m,) + time_at_error(uniform, m, num(cam, m) * (1 + EQUAL_ERROR)) for m in metrics]
                if any(t is None for _, t, _ in est):
                    row["how"] = "; ".join(f"{m}: {h}" for m, t, h in est if t is None)
                else:
                    m, t, h = max(est, key=lambda e: e[1])
                    row.update(time=t, how=f"no uniform bake as good on both: {m} {h}")
            if row["time"]:
                row["ratio"] = row["time"] / t_cam
            rows.append(row)
    return rows


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
    cpu = m.get("cpu", "unknown CPU")
    extra = [f"{m['cores']} cores" if m.get("cores") else "",
             f"{fmt(m['memory_gib'])} GiB" if m.get("memory_gib") else ""]
    out.append(f"- **Machine:** {cpu}" + (f" ({', '.join(e for e in extra if e)})" if any(extra) else "") +
               (f"; load average before the sweep {', '.join(fmt(x, 2) for x in m['load_before'])}"
                if m.get("load_before") else ""))
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
            parts.append(f"## {KNOB_TITLES.get(k, k)}\n\nKnob `{k}`.\n\n{table}")
    if not scenes:
        parts.append("_No scenes in the results._")
    return "\n\n".join(parts) + "\n"


# ------------------------------------------------------------------ plot --

def place_labels(ax, points, metric):
    """Short labels right of the points, pushed down when they would overlap an earlier one."""
    ax.set_xlim(*ax.get_xlim())  # freeze the autoscaled limits so pixel positions are final
    ax.set_ylim(*ax.get_ylim())
    taken, pt = [], ax.figure.dpi / 72  # boxes in pixels; offsets in points

    def free(x0, y0, w):
        return all(x0 + w < a or x0 > a + aw or y0 + 9 * pt < b or y0 > b + 9 * pt for a, b, aw in taken)

    for p in sorted(points, key=lambda p: (p["time_s"], -num(p, metric))):
        text = label(p)[:16]
        x, y = ax.transData.transform((p["time_s"], num(p, metric)))
        w = (4.8 * len(text) + 2) * pt
        tries = [(5, 4), (5, -13), (-5 - w / pt, 4), (-5 - w / pt, -13)] + [(5, 4 + 10 * k) for k in (1, -2, 2, -3)]
        dx, dy = next(((dx, dy) for dx, dy in tries if free(x + dx * pt, y + dy * pt, w)), tries[0])
        taken.append((x + dx * pt, y + dy * pt, w))
        ax.annotate(text, (p["time_s"], num(p, metric)), xytext=(dx, dy), textcoords="offset points",
                    fontsize=8, color="#333333")


def plot_scene(name, scene, results):
    """PNG bytes (1200x800 px) of FLIP (top) and RMSE (bottom) against time
    (log x) for one scene, or None when no point has both a time and an error."""
    import io

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = [p for p in with_time(scene.get("points") or []) if (p["time_s"] or 0) > 0]
    panels = [m for m in ("flip", "rmse") if any(num(p, m) is not None for p in pts)]
    if not panels:
        return None
    knobs = [k for k in knobs_in({"scenes": {name: scene}})
             if any(p.get("knob") == k and any(num(p, m) is not None for m in panels) for p in pts)]
    cmap = plt.get_cmap("tab10" if len(knobs) <= 10 else "tab20")
    colour = {k: cmap(i % cmap.N) for i, k in enumerate(knobs)}
    versions = sorted({str(p.get("blender")) for p in pts})
    marker = {v: "osD^v"[i % 5] for i, v in enumerate(versions)}
    ref = scene.get("reference") or {}
    floors = {"flip": (num(ref, "noise_flip"), "noise floor (FLIP, 2 ref. seeds)"),
              "rmse": (num(ref, "reference_rmse") if num(ref, "reference_rmse") is not None else
                       (num(ref, "noise_rmse") / 2 if num(ref, "noise_rmse") is not None else None),
                       "reference noise (RMSE / 2)")}
    names = {"flip": "mean FLIP (LDR)", "rmse": "RMSE (linear radiance)"}

    plt.rcParams.update({"font.size": 11})
    fig = plt.figure(figsize=(12, 8), dpi=100)
    grid = fig.add_gridspec(len(panels), 1, height_ratios=[3, 1.3][:len(panels)], hspace=0.08,
                            left=0.08, right=0.76, top=0.88, bottom=0.08)
    axes = []
    for row, metric in enumerate(panels):
        ax = fig.add_subplot(grid[row], sharex=axes[0] if axes else None)
        axes.append(ax)
        mp = [p for p in pts if num(p, metric) is not None]
        for p in mp:
            ax.scatter(p["time_s"], num(p, metric), s=46 if row == 0 else 28, color=colour[p.get("knob")],
                       marker=marker[str(p.get("blender"))], zorder=3, edgecolors="black", linewidths=0.4)
        front = pareto_front(mp, "time_s", metric)
        if front:
            xs = [p["time_s"] for p in front]
            ys = [num(p, metric) for p in front]
            ax.step(xs, ys, where="post", color="black", lw=1.3, alpha=0.7, zorder=2, label="Pareto front")
            ax.scatter(xs, ys, s=(190 if row == 0 else 110), facecolors="none", edgecolors="black",
                       linewidths=1.4, zorder=4)
            k = knee(front, "time_s", metric)
            if k is not None:
                ax.scatter([k["time_s"]], [num(k, metric)], marker="*", s=(380 if row == 0 else 200),
                           color="gold", edgecolors="black", zorder=5, label="knee")
                if row == 0:
                    ax.annotate("knee", (k["time_s"], num(k, metric)), xytext=(-10, -20),
                                textcoords="offset points", fontsize=11, weight="bold")
        floor, flabel = floors[metric]
        if floor is not None and floor > 0:
            ax.axhline(floor, ls="--", color="tab:red", lw=1.3, label=flabel, zorder=1)
        ys = [num(p, metric) for p in mp] + ([floor] if floor else [])
        pos = [y for y in ys if y > 0]
        if pos and max(pos) / min(pos) > 30:
            ax.set_yscale("log")
        else:
            ax.set_ylim(bottom=0)
        ax.set_xscale("log")
        ax.set_ylabel(names[metric])
        if row == 0:
            place_labels(ax, mp, metric)
        ax.grid(True, which="both", alpha=0.25)
        if row < len(panels) - 1:
            ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("time per frame, s (bake + render, best run; log scale)")

    from matplotlib.lines import Line2D
    handles = [Line2D([], [], ls="", marker="o", color=colour[k], markeredgecolor="black", label=k) for k in knobs]
    if len(versions) > 1:
        handles += [Line2D([], [], ls="", marker=marker[v], color="grey", label=f"Blender {v}") for v in versions]
    h, _ = axes[0].get_legend_handles_labels()
    handles += h
    handles.append(Line2D([], [], ls="", marker="o", markersize=12, markerfacecolor="none",
                          markeredgecolor="black", label="on the front"))
    axes[0].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, frameon=False,
                   title="knob", title_fontsize=10)

    m, st = results.get("machine") or {}, results.get("settings") or {}
    size = st.get("image_size")
    bits = [f"{m.get('cpu', 'unknown CPU')}" + (f", {m['cores']} cores" if m.get("cores") else ""),
            "Blender " + " / ".join(str(v) for v in (results.get("blender") or {}).values()) if results.get("blender")
            else "", f"{size[0]}×{size[1]} px" if size else "",
            f"reference {ref['samples']} spp" if ref.get("samples") else "",
            f"best of {st['runs_per_point']} runs" if st.get("runs_per_point") else ""]
    fig.suptitle(f"{name}: image error against time (lower left is better)", fontsize=15, weight="bold", y=0.975)
    fig.text(0.5, 0.925, " · ".join(b for b in bits if b), ha="center", fontsize=10, color="#444444")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return buf.getvalue()


# ----------------------------------------------------------------- files --

def atomic_write(path, data):
    """Write bytes or text to `path` via a temporary file in the same folder + os.replace."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode() if isinstance(data, str) else data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def splice(old, generated):
    """`old` with the text between the markers replaced by `generated`. Without
    markers, a title is created (empty `old`) or the block is appended."""
    block = f"{START}\n{generated.rstrip()}\n{END}"
    if START in old and END in old and old.index(START) < old.index(END):
        head, rest = old.split(START, 1)
        return head + block + rest.split(END, 1)[1]
    if not old.strip():
        return ("# Accuracy: the speed/accuracy trade, measured\n\n"
                "Regenerate the tables and plots with `python bench/accuracy/report.py`; "
                "text outside the generated markers is kept.\n\n" + block + "\n")
    return old.rstrip("\n") + "\n\n" + block + "\n"


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
    atomic_write(docs, splice(old, render_markdown(results, rels)))
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
