"""Analysis of the accuracy sweep's results (bench/results/accuracy.json), beside
pareto.py: each point's cost, the scene's Pareto front and knee over all knobs,
and the camera-aware bakes against the uniform bakes at equal error (matched
errors when every point has them). Pure functions; report.py writes them up,
plot.py draws them.
"""
import math

from accuracy.pareto import knee, pareto_front
from accuracy.pareto import number as num

KNOB_ORDER = ["tier", "procedural", "bake_resolution", "bake_half", "noise_detail", "lod", "tolerance",
              "skip_empty", "camera_aware", "step_rate", "samples", "volume_biased", "preview_resolution"]


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

