"""The sweep's CLI consumer (bench/accuracy/runner.py) reads `cloudgen bake --json`
(docs/cli_protocol.md) through addon/cli_events.py: canned event lines, and a
fake `cloudgen` that prints them; the results writer (results.py) reproduces
the committed accuracy.json from the committed cache."""
import json
import pathlib
import sys

import pytest
from accuracy import results, runner
from accuracy.config import SweepConfig

ROOT = pathlib.Path(__file__).resolve().parents[2]

PLAN = {"event": "plan", "protocol": 1, "files": [{"frame": None, "path": "cloud.vdb"}], "grid": [48, 48, 36],
        "voxel": 0.0833, "memory_gib": 0.01, "threads": 2, "preset": "cumulus"}
CAMERA = {"event": "camera", "visible": True, "nearest_depth": 7.5, "footprint": 0.0123, "voxel": 0.0123,
          "margin": 0.5}
WROTE = {"event": "wrote", "path": "cloud.vdb", "frame": None, "active_voxels": 2390, "grid": [326, 326, 245],
         "voxel": 0.012345678901, "bytes": 20480, "seconds": 0.02, "tiles_total": 1200, "tiles_culled": 900}


def lines(*events):
    return "".join(json.dumps(e) + "\n" for e in events)


def test_camera_figures_from_the_wrote_event():
    ev = runner.bake_events(lines(PLAN, CAMERA, {"event": "progress", "fraction": 0.5}, WROTE))
    assert runner.camera_figures(ev) == {"camera_voxel": 0.012345678901, "visible_tiles": 300, "total_tiles": 1200}
    assert runner.camera_figures(runner.bake_events(lines(PLAN, WROTE))) == {}, "no camera event: no camera figures"


def test_bake_events_rejects_other_protocols_and_human_lines():
    with pytest.raises(runner.cli_events.ProtocolError):
        runner.bake_events(lines(dict(PLAN, protocol=2)))
    with pytest.raises(runner.cli_events.ProtocolError):
        runner.bake_events("wrote cloud.vdb (2390 active voxels of 48x48x36, 0.02 MiB, 0.02 s)\n")


FAKE = """\
#!{python}
import json, pathlib, sys
args = sys.argv[1:]
if args[:2] == ["bake", "--help"]:
    print({help!r})
    sys.exit(0)
log = pathlib.Path({log!r})
log.write_text(log.read_text() + json.dumps(args) + "\\n" if log.exists() else json.dumps(args) + "\\n")
out = args[args.index("--output") + 1]
if {fail!r}:
    print(json.dumps({{"event": "error", "code": 2, "message": "--resolution: out of range"}}))
    sys.exit(2)
pathlib.Path(out).write_bytes(b"v" * 3 * 2 ** 19)
print(json.dumps({plan!r}))
print(json.dumps(dict({wrote!r}, path=out)))
"""


def fake_cli(tmp_path, fail=False, help_text="--quality TIER --camera FILE --json"):
    path = tmp_path / "cloudgen"
    path.write_text(FAKE.format(python=sys.executable, help=help_text, log=str(tmp_path / "calls.log"), fail=fail,
                                plan=PLAN, wrote=WROTE))
    path.chmod(0o755)
    return path


def test_bake_runs_the_cli_with_json(tmp_path):
    cfg = SweepConfig(out=tmp_path, cloudgen=fake_cli(tmp_path), bake_runs=2)
    work = tmp_path / "work"
    work.mkdir()
    res = runner.bake(cfg, "cumulus", {"resolution": 128, "half": True, "lod": False, "tolerance": 0.01,
                                       "skip": True}, work / "cloud.vdb", work)
    calls = [json.loads(x) for x in (tmp_path / "calls.log").read_text().splitlines()]
    assert len(calls) == 2 and all(c[-1] == "--json" for c in calls), calls
    assert res["bake_cmd"] == "bake --quiet --preset cumulus --output cloud.vdb --resolution 128 --tolerance 0.01 " \
                              "--half --no-lod", res["bake_cmd"]
    assert res["file_mib"] == 1.5 and len(res["bake_s_all"]) == 2 and res["bake_s"] == min(res["bake_s_all"])
    assert "camera_voxel" not in res, res
    tier = runner.bake_cmd(cfg, "cumulus", {"resolution": 128, "quality": "draft"}, "x.vdb")
    assert tier[-2:] == ["--quality", "draft"], tier


def test_bake_failure_reports_the_error_event(tmp_path):
    cfg = SweepConfig(out=tmp_path, cloudgen=fake_cli(tmp_path, fail=True))
    with pytest.raises(RuntimeError, match=r"bake failed \(exit 2\).*\n--resolution: out of range"):
        runner.bake(cfg, "cumulus", {"resolution": 0}, tmp_path / "cloud.vdb", tmp_path)


def test_bake_needs_a_cli_with_json(tmp_path):
    cfg = SweepConfig(out=tmp_path, cloudgen=fake_cli(tmp_path, help_text="--quality TIER --camera FILE"))
    with pytest.raises(RuntimeError, match="has no --json"):
        runner.bake(cfg, "cumulus", {"resolution": 64}, tmp_path / "cloud.vdb", tmp_path)
    assert not (tmp_path / "calls.log").exists(), "no bake was run"


def test_results_from_the_committed_cache_are_the_committed_results(tmp_path):
    committed = json.loads((ROOT / "bench/results/accuracy.json").read_text())
    cfg = SweepConfig(out=tmp_path, runs=committed["settings"]["runs_per_point"], machine=committed["machine"])
    (tmp_path / "accuracy_cache").symlink_to(ROOT / "bench/results/accuracy_cache")
    results.write_results(cfg)
    assert json.loads(cfg.results.read_text()) == committed


def test_results_only_keeps_the_measuring_machine(tmp_path, capsys):
    from accuracy import sweep

    measured = {"cpu_model": "Measuring CPU", "nproc": 2, "load_average": [2.5, 2.0, 1.5]}
    (tmp_path / "accuracy.json").write_text(json.dumps({"machine": measured}))
    assert sweep.main(["--results-only", "--out", str(tmp_path)]) == 0
    got = json.loads((tmp_path / "accuracy.json").read_text())
    assert got["machine"] == measured and got["scenes"] == {}, got
    fresh = tmp_path / "fresh"
    assert sweep.main(["--results-only", "--out", str(fresh)]) == 0
    assert json.loads((fresh / "accuracy.json").read_text())["machine"]["cpu_model"], "else this machine"
