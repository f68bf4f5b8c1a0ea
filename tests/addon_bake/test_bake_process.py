"""addon/bake_process.py against the real CLI (build/bin/cloudgen), plain pytest, no bpy:
progress reaches 100, cancel leaves no file, I/O and argument errors carry the
CLI's one-line message naming the path, a sequence writes every frame, a
full disk (simulated with RLIMIT_FSIZE) leaves no file."""
import importlib.util
import os
import pathlib
import resource
import signal
import subprocess
import sys
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"
_spec = importlib.util.spec_from_file_location("cloudgen_bake_process", ROOT / "addon" / "bake_process.py")
bp = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = bp  # dataclasses look their module up
_spec.loader.exec_module(bp)

pytestmark = pytest.mark.skipif(not CLI.is_file(), reason="build/bin/cloudgen not built")
CUMULUS = {"preset": "cumulus"}


def files_in(d):
    return sorted(p.name for p in pathlib.Path(d).iterdir())  # hidden temporaries included


def test_progress_reaches_100_and_file_reads(tmp_path):
    seen = []
    out = tmp_path / "c.vdb"
    result = bp.run_bake(CLI, CUMULUS, 24, str(out), on_progress=seen.append)
    assert result.ok and result.paths == [str(out)]
    assert seen and seen[-1] == 100.0 and seen == sorted(seen)
    assert files_in(tmp_path) == ["c.vdb"]
    info = subprocess.run([str(CLI), "info", str(out)], capture_output=True, text=True, check=True)
    assert "grid: density" in info.stdout and "fog volume" in info.stdout


def test_poll_loop_and_params_file_removed(tmp_path):
    job = bp.BakeJob(CLI, {"preset": "stratus", "seed": 3}, 16, str(tmp_path / "s.vdb")).start()
    params_file = job._params_file
    assert os.path.isfile(params_file)
    while job.poll() is None:
        time.sleep(0.01)
    assert job.poll().ok and job.progress == 100.0
    assert not os.path.exists(params_file)


def test_sequence_writes_every_frame(tmp_path):
    seen = []
    result = bp.run_bake(CLI, CUMULUS, 12, str(tmp_path / "seq_####.vdb"), frames=(3, 5), fps=24,
                         on_progress=seen.append)
    want = [str(tmp_path / f"seq_{f:04d}.vdb") for f in (3, 4, 5)]
    assert result.paths == want
    assert files_in(tmp_path) == [f"seq_{f:04d}.vdb" for f in (3, 4, 5)]
    assert seen[-1] == 100.0
    assert bp.sequence_paths(str(tmp_path / "x.vdb"), 1, 2) == [str(tmp_path / "x_0001.vdb"),
                                                                str(tmp_path / "x_0002.vdb")]


def test_cancel_leaves_no_partial_file(tmp_path):
    out = tmp_path / "big.vdb"
    # large enough to be still running when cancelled; one thread to spare the machine
    job = bp.BakeJob(CLI, CUMULUS, 400, str(out), extra=("--threads", "1", "--no-skip")).start()
    while not job.stdout_lines and job.poll() is None:
        time.sleep(0.005)
    job.cancel()
    result = job.wait(timeout=120)
    assert result.cancelled and not result.ok, result
    assert "cancelled" in result.message
    assert files_in(tmp_path) == []


def test_unwritable_path_names_the_path(tmp_path):
    blocker = tmp_path / "not_a_dir"
    blocker.write_text("x")
    out = blocker / "c.vdb"
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(CLI, CUMULUS, 8, str(out))
    assert err.value.code in (bp.IO_ERROR, bp.BAD_ARGUMENT)
    assert str(blocker) in str(err.value), str(err.value)
    assert "\n" not in str(err.value)
    assert files_in(tmp_path) == ["not_a_dir"]


def test_missing_directory_is_a_bad_argument(tmp_path):
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(CLI, CUMULUS, 8, str(tmp_path / "nope" / "c.vdb"))
    assert err.value.code == bp.BAD_ARGUMENT
    assert str(tmp_path / "nope") in str(err.value)


def test_bad_parameter_is_reported_in_one_line(tmp_path):
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(CLI, {"preset": "cumulus", "density": -5}, 8, str(tmp_path / "c.vdb"))
    assert err.value.code == bp.BAD_ARGUMENT
    assert "density" in str(err.value) and "\n" not in str(err.value)
    assert files_in(tmp_path) == []


def _small_disk():
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))  # writes past 4 KiB fail (EFBIG)
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


def test_full_disk_leaves_no_file(tmp_path, monkeypatch):
    real_popen = subprocess.Popen

    def popen(cmd, **kw):
        if "bake" in cmd:
            kw["preexec_fn"] = _small_disk
        return real_popen(cmd, **kw)

    monkeypatch.setattr(bp.subprocess, "Popen", popen)
    out = tmp_path / "full.vdb"
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(CLI, CUMULUS, 48, str(out))
    assert err.value.code == bp.IO_ERROR
    assert str(out) in str(err.value)
    assert files_in(tmp_path) == []


def test_missing_executable():
    with pytest.raises(bp.BakeError, match="not found"):
        bp.BakeJob(None, CUMULUS, 8, "/tmp/x.vdb")
