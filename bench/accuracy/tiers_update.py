"""Write the benchmark's measured figures into the quality tiers data file.

    python bench/accuracy/tiers_update.py [--results bench/results/accuracy.json]
                                          [--tiers native/presets/tiers.json] [--check]

Each tier's "measured" object gets, per scene, the figures of the sweep's
"tier" points (bench/accuracy/sweep.py): the tier's bake rendered with its
render settings (render_s, bake_s, rmse, flip, field_rms) and its render
settings on the procedural material (procedural_render_s, procedural_rmse,
procedural_flip). The add-on shows them in its tooltips and `cloudgen tiers
--json` prints them. --check exits 1 when the file differs from what it would
write (tests/bench/test_tiers_measured.py runs that), so the numbers in the
data file are the numbers in the results.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
if str(ROOT / "bench") not in sys.path:
    sys.path.insert(0, str(ROOT / "bench"))
from common import atomic_write

FIGURES = ("render_s", "bake_s", "rmse", "flip", "field_rms")
PROCEDURAL_FIGURES = ("render_s", "rmse", "flip")


def _round(v):
    return None if v is None else float(f"{float(v):.3g}")


def measured_from_results(results: dict) -> dict:
    """tier name -> {scene: {figure: value}} from the results' "tier" points, with the image
    size they were rendered at ("image": "WxH") and the day of the latest ("measured_on"): a
    tooltip's render time means little without them, and a preset changed since is told by the
    date (docs/accuracy.md)."""
    out: dict = {}
    size = (results.get("settings") or {}).get("image_size")
    for scene, data in (results.get("scenes") or {}).items():
        for p in data.get("points", []):
            if p.get("knob") != "tier":
                continue
            entry = out.setdefault(p["setting"], {}).setdefault(scene, {})
            if size:
                entry["image"] = f"{int(size[0])}x{int(size[1])}"
            day = str(p.get("measured_at") or "")[:10]
            if day and day > entry.get("measured_on", ""):
                entry["measured_on"] = day
            if p.get("variant") == "procedural":
                for k in PROCEDURAL_FIGURES:
                    if p.get(k) is not None:
                        entry["procedural_" + k] = _round(p[k])
            else:
                for k in FIGURES:
                    if p.get(k) is not None:
                        entry[k] = _round(p[k])
    return out


def _section(obj) -> str:
    return json.dumps(obj, separators=(", ", ": "))


def render_tiers(tiers: dict) -> str:
    """The data file's layout: one line per settings section, measured per scene."""
    lines = ["{"]
    names = list(tiers)
    for i, name in enumerate(names):
        t = tiers[name]
        lines.append(f'  "{name}": {{')
        body = [f'    "label": {json.dumps(t["label"])}', f'    "description": {json.dumps(t["description"])}']
        for key in ("render", "bake", "preview"):
            body.append(f'    "{key}": {_section(t[key])}')
        measured = t.get("measured") or {}
        if measured:
            inner = [f'      "{scene}": {_section(m)}' for scene, m in measured.items()]
            body.append('    "measured": {\n' + ",\n".join(inner) + "\n    }")
        else:
            body.append('    "measured": {}')
        lines.append(",\n".join(body))
        lines.append("  }" + ("," if i + 1 < len(names) else ""))
    lines.append("}")
    return "\n".join(lines) + "\n"


def updated_text(tiers_text: str, results: dict) -> str:
    tiers = json.loads(tiers_text)
    measured = measured_from_results(results)
    for name, t in tiers.items():
        t["measured"] = measured.get(name, {})
    return render_tiers(tiers)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default=str(ROOT / "bench" / "results" / "accuracy.json"))
    ap.add_argument("--tiers", default=str(ROOT / "native" / "presets" / "tiers.json"))
    ap.add_argument("--check", action="store_true", help="exit 1 if the file is not up to date")
    opts = ap.parse_args(argv)
    results = json.loads(pathlib.Path(opts.results).read_text())
    path = pathlib.Path(opts.tiers)
    current = path.read_text()
    new = updated_text(current, results)
    if opts.check:
        if new != current:
            print(f"{path}: measured figures differ from {opts.results}; run bench/accuracy/tiers_update.py",
                  file=sys.stderr)
            return 1
        return 0
    if new != current:
        atomic_write(path, new)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
