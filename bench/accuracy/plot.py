"""The accuracy report's plots: per scene, FLIP and RMSE against bake + render
time with the Pareto front and its knee (analysis.py), as PNG bytes (matplotlib, Agg)."""
from accuracy.analysis import knobs_in, label, with_time
from accuracy.pareto import knee, pareto_front
from accuracy.pareto import number as num


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
    bits = [f"{m.get('cpu_model') or 'unknown CPU'}" + (f", {m['nproc']} cores" if m.get("nproc") else ""),
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

