"""python -m cloudgen_dask on a LocalCluster of 2 worker processes (loopback):
bricks and frames equal the single-process bake voxel for voxel (exact: the same
kernel on the same voxels), a worker killed mid-unit and an interrupted run lose
nothing and recompute nothing finished, an unwritable unit fails with one line."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from cloudgen_dask import runner
from conftest import CLI, ROOT
from vdb_voxels import read_voxels


def single_bake(out, *args):
    r = subprocess.run([str(CLI), "bake", *map(str, args), "--output", str(out), "--quiet"], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr


def settings(out, *args, bricks=1, work=None):
    return runner.Settings(bake_args=[*map(str, args), "--output", str(out), "--threads", "1"], cli=str(CLI),
                           bricks=bricks, work_dir=str(work) if work else None, progress=False)


def assert_same_voxels(a, b):
    va, oa, sa = read_voxels(a)
    vb, ob, sb = read_voxels(b)
    assert (oa, sa) == (ob, sb), (a, b, oa, ob, sa, sb)
    assert len(va) == len(vb) and len(va) > 0, (a, b, len(va), len(vb))
    diff = [c for c in va if va[c] != vb.get(c)]
    assert not diff, f"{len(diff)} voxels differ, e.g. {diff[0]}: {va[diff[0]]} vs {vb.get(diff[0])}"


def leftovers(folder):
    return sorted(p.name for p in folder.rglob("*") if p.is_file() and (".tmp" in p.name or "cloudgen-" in p.name))


def test_bricks_equal_the_single_bake(client, tmp_path):
    args = ("--preset", "cumulus", "--resolution", 72)
    single_bake(tmp_path / "whole.vdb", *args)
    summary = runner.run(settings(tmp_path / "split.vdb", *args, bricks=5), client=client)
    assert summary.units == 5 and summary.computed == 5 and summary.merged, summary
    assert_same_voxels(tmp_path / "whole.vdb", tmp_path / "split.vdb")
    assert leftovers(tmp_path) == [] and not any((tmp_path / ".cloudgen-dask").glob("bricks_*"))
    again = runner.run(settings(tmp_path / "split.vdb", *args, bricks=5), client=client)
    assert again.computed == 0 and again.skipped == 5 and not again.merged, again  # the joined file holds the key


def test_frames_equal_cloudgen_frames(client, tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    args = ("--preset", "cumulus", "--resolution", 24, "--frames", "1-4")
    single_bake(tmp_path / "a" / "f_####.vdb", *args)
    summary = runner.run(settings(tmp_path / "b" / "f_####.vdb", *args), client=client)
    assert summary.units == 4 and summary.computed == 4, summary
    for f in range(1, 5):
        assert_same_voxels(tmp_path / "a" / f"f_{f:04d}.vdb", tmp_path / "b" / f"f_{f:04d}.vdb")


def test_still_frames_are_baked_once_and_copied(client, tmp_path):
    params = tmp_path / "still.json"
    params.write_text(json.dumps({"preset": "stratus", "evolution": 0, "wind_strength": 0}))
    summary = runner.run(settings(tmp_path / "s.vdb", "--params", params, "--resolution", 16, "--frames", "1-3"),
                         client=client)
    assert summary.units == 1 and summary.computed == 1 and summary.copied == 2, summary
    data = [(tmp_path / f"s_{f:04d}.vdb").read_bytes() for f in (1, 2, 3)]
    assert data[0] == data[1] == data[2]


def test_worker_killed_mid_unit(client, tmp_path):
    """SIGKILL one worker while it runs a unit: Dask runs the unit again, the output is exact."""
    args = ("--preset", "cumulus", "--resolution", 120)
    single_bake(tmp_path / "whole.vdb", *args)
    box = {}

    def go():
        try:
            box["summary"] = runner.run(settings(tmp_path / "split.vdb", *args, bricks=4), client=client)
        except BaseException as exc:  # noqa: BLE001 - reported by the assertion below
            box["error"] = exc

    thread = threading.Thread(target=go)
    thread.start()
    pids = client.run(os.getpid)
    killed = None
    deadline = time.time() + 120
    while killed is None and time.time() < deadline and thread.is_alive():
        busy = [w for w, tasks in client.processing().items() if tasks]
        if busy:
            killed = pids[busy[0]]
            os.kill(killed, signal.SIGKILL)
        time.sleep(0.05)
    thread.join(timeout=600)
    assert killed is not None, "no unit was seen running"
    assert "error" not in box, box.get("error")
    assert box["summary"].units == 4, box["summary"]
    assert_same_voxels(tmp_path / "whole.vdb", tmp_path / "split.vdb")
    assert leftovers(tmp_path) == []


def test_interrupted_run_resumes_without_recomputing(client, tmp_path):
    args = ("--preset", "cumulus", "--resolution", 64)
    finished = []

    def stop_after_two(result):
        finished.append(result["name"])
        if len(finished) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        runner.run(settings(tmp_path / "c.vdb", *args, bricks=6), client=client, on_unit=stop_after_two)
    assert not (tmp_path / "c.vdb").exists()
    # nothing of the first run still runs (its CLIs get SIGTERM with their worker). The workers'
    # restart is waited for up to 10 min, not Dask's 2: beside a render on both cores (the main
    # job during a full test run) one worker took longer than 120 s to come back. A bound on
    # liveness, not a speed assertion.
    client.restart(timeout=600)
    bricks = sorted((tmp_path / ".cloudgen-dask").glob("bricks_*/*.vdb"))
    assert 2 <= len(bricks) < 6, bricks  # the finished units are on disk, not all of them
    summary = runner.run(settings(tmp_path / "c.vdb", *args, bricks=6), client=client)
    assert summary.skipped == len(bricks) and summary.computed == 6 - len(bricks), (summary, bricks)
    single_bake(tmp_path / "whole.vdb", *args)
    assert_same_voxels(tmp_path / "whole.vdb", tmp_path / "c.vdb")


def test_unit_that_cannot_write_fails_with_one_line(tmp_path):
    """Brick 1's file name is taken by a folder: the plan already names that unit (exit 2),
    nothing is baked or joined."""
    out = tmp_path / "c.vdb"
    cmd = [sys.executable, "-m", "cloudgen_dask", "bake", "--no-progress", "--workers", "1", "--bricks", "3",
           "--preset", "cumulus", "--resolution", 24, "--output", out]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    dry = subprocess.run([str(CLI), "bake", "--preset", "cumulus", "--resolution", "24", "--output", str(out),
                          "--dry-run", "--json"], capture_output=True, text=True, check=True)
    whole_key = json.loads(dry.stdout.splitlines()[0])["files"][0]["key"]
    blocker = tmp_path / ".cloudgen-dask" / f"bricks_{whole_key}" / "brick_00001_of_00003.vdb"
    blocker.mkdir(parents=True)
    r = subprocess.run(list(map(str, cmd)), capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("cloudgen-dask: error:")]
    assert len(errors) == 1 and "unit brick 1/3" in errors[0], r.stderr
    assert not out.exists() and leftovers(tmp_path) == []
    assert not list(blocker.parent.glob("*.vdb*")) or [p.name for p in blocker.parent.iterdir()] == [blocker.name]


def test_worker_that_cannot_write_names_the_unit(client, tmp_path):
    """The same on a worker (the output became unwritable after planning): UnitError naming the unit."""
    from cloudgen_dask import units

    out = tmp_path / "taken.vdb"
    out.mkdir()
    unit = units.Unit("brick 2/7", "0-0", str(out), ("bake", "--preset", "cumulus", "--resolution", "8",
                                                     "--output", str(out)), (8, 8, 6), 384)
    with pytest.raises(units.UnitError, match=r"unit brick 2/7 .*is a directory"):
        client.submit(units.run_unit, unit, str(CLI), pure=False).result()
    assert [p.name for p in tmp_path.iterdir()] == ["taken.vdb"] and not any(out.iterdir())


def test_bad_options_exit_2(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    r = subprocess.run([sys.executable, "-m", "cloudgen_dask", "bake", "--preset", "cumulus", "--resolution", "0",
                        "--output", str(tmp_path / "x.vdb")], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2 and "--resolution" in r.stderr, (r.returncode, r.stderr)


def test_runner_speaks_the_json_protocol(tmp_path):
    """--json: stdout is protocol events only (progress, then summary; error with the exit code)."""
    sys.path.insert(0, str(ROOT / "addon"))
    import cli_events

    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    base = [sys.executable, "-m", "cloudgen_dask", "bake", "--json", "--workers", "1", "--preset", "stratus"]
    r = subprocess.run([*base, "--resolution", "12", "--frames", "1-2", "--output", str(tmp_path / "s_##.vdb")],
                       capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    events = [cli_events.parse(line) for line in r.stdout.splitlines() if line.strip()]
    kinds = [e["event"] for e in events]
    assert kinds == ["progress", "progress", "summary"], kinds
    assert events[-2]["fraction"] == 1.0 and events[-1]["computed"] == 2, events
    bad = subprocess.run([*base, "--resolution", "0", "--output", str(tmp_path / "x.vdb")], capture_output=True,
                         text=True, env=env, timeout=300)
    (err,) = [cli_events.parse(line) for line in bad.stdout.splitlines() if line.strip()]
    assert bad.returncode == 2 and err["event"] == "error" and err["code"] == 2 and "--resolution" in err["message"]
