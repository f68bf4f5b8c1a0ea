"""The tiers data file carries the benchmark's measured figures
(bench/accuracy/tiers_update.py): its layout round-trips, the figures come
from the "tier" points of the results, and the committed file is up to date."""
import json
import pathlib

from accuracy import tiers_update

ROOT = pathlib.Path(__file__).resolve().parents[2]
TIERS = ROOT / "native" / "presets" / "tiers.json"
RESULTS = ROOT / "bench" / "results" / "accuracy.json"


def test_layout_round_trips_without_results():
    text = TIERS.read_text()
    data = json.loads(text)
    again = json.loads(tiers_update.render_tiers(data))
    assert again == data, "render_tiers must keep every value"
    assert list(again) == list(data), "and the tiers' order"


def test_figures_come_from_the_tier_points():
    results = {"scenes": {"cumulus": {"points": [
        {"knob": "tier", "setting": "draft", "variant": "vdb", "render_s": 1.23456, "bake_s": 0.1, "rmse": 0.01,
         "flip": 0.05, "field_rms": 0.002},
        {"knob": "tier", "setting": "draft", "variant": "procedural", "render_s": 2.0, "rmse": 0.02, "flip": 0.04},
        {"knob": "samples", "setting": "16", "render_s": 9.0, "flip": 0.5},
    ]}}}
    m = tiers_update.measured_from_results(results)
    assert m == {"draft": {"cumulus": {"render_s": 1.23, "bake_s": 0.1, "rmse": 0.01, "flip": 0.05,
                                       "field_rms": 0.002, "procedural_render_s": 2.0,
                                       "procedural_rmse": 0.02, "procedural_flip": 0.04}}}, m
    text = tiers_update.updated_text(TIERS.read_text(), results)
    data = json.loads(text)
    assert data["draft"]["measured"]["cumulus"]["flip"] == 0.05
    assert data["final"]["measured"] == {}, "tiers without points get an empty measured object"


def test_committed_tiers_file_matches_the_committed_results():
    assert RESULTS.exists(), f"{RESULTS} is committed with the benchmark; it is missing"
    results = json.loads(RESULTS.read_text())
    expected = tiers_update.updated_text(TIERS.read_text(), results)
    assert any(t["measured"] for t in json.loads(TIERS.read_text()).values()), "the tiers carry measured figures"
    assert json.loads(TIERS.read_text()) == json.loads(expected), (
        "native/presets/tiers.json's measured figures differ from bench/results/accuracy.json; "
        "run bench/accuracy/tiers_update.py")
