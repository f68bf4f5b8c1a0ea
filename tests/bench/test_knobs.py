"""The sweep's knob rows (bench/accuracy/knobs.py) make the points the former
sweep.py made (its table + if-chain), captured before the refactor in
data/knob_points_before.json with fixed tiers and preset noise details: same
points, same key order (the cache files store them), same settings per scene."""
import json
import pathlib

import pytest
from accuracy import knobs, scenes
from accuracy.config import SweepConfig

BEFORE = json.loads((pathlib.Path(__file__).parent / "data" / "knob_points_before.json").read_text())


def points_of(quick):
    cfg = SweepConfig(out=pathlib.Path("/nonexistent"), quick=quick, _tiers=BEFORE["tiers"])
    per = {}
    for scene in scenes.SCENES:
        pts = []
        for knob in knobs.KNOBS:
            if knob.runs_on(scene):
                for setting in knob.settings_for(scene, cfg, {"noise_detail": BEFORE["noise_detail"][scene]}):
                    pts += knob.points(setting, cfg)
        per[scene] = pts
    return per


@pytest.mark.parametrize("mode", ["full", "quick"])
def test_knob_rows_make_the_points_of_before(mode):
    got = points_of(mode == "quick")
    want = BEFORE[mode]
    assert list(got) == list(want)
    for scene in want:
        g = [(p["knob"], p["setting"], p.get("variant")) for p in got[scene]]
        w = [(p["knob"], p["setting"], p.get("variant")) for p in want[scene]]
        assert g == w, f"{mode} {scene}: settings differ"
        for a, b in zip(got[scene], want[scene]):
            assert json.dumps(a, ensure_ascii=False) == json.dumps(b, ensure_ascii=False), f"{mode} {scene}:\n{a}\n{b}"


def test_knob_names_and_order():
    assert [k.name for k in knobs.KNOBS] == BEFORE["knobs"]
    assert set(knobs.BY_NAME) == set(BEFORE["knobs"])


def test_every_knob_titles_its_report_section():
    from accuracy import report

    assert all(k.title and k.title != k.name for k in knobs.KNOBS)
    results = {"scenes": {"s": {"points": [{"knob": "lod", "setting": "on@64", "time_s": 1.0, "flip": 0.1},
                                           {"knob": "new_knob", "setting": "x", "time_s": 2.0, "flip": 0.2}]}}}
    text = report.render_markdown(results)
    assert "## Level of detail (octaves capped at the voxel size)\n\nKnob `lod`." in text, text
    assert "## new_knob\n\nKnob `new_knob`." in text, "a knob without a row is titled by its name"
