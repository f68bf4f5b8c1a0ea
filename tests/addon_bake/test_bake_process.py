"""addon/bake_process.py against the real CLI (build/bin/cloudgen, `bake --json`), plain
pytest, no bpy: progress reaches 100, cancel leaves no file, I/O and argument errors
carry the CLI's one-line message naming the path, a sequence writes every frame and
the files are the plan's (the last run of '#' is the frame number), a full disk
(simulated with RLIMIT_FSIZE) leaves no file; with canned CLIs (small scripts that
print fixed lines): an error event wins over stderr, stderr is the fallback, output
that breaks the protocol fails the bake. Exact comparisons throughout (no tolerance:
names, counts and codes)."""
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


def _load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up; bake_process finds cli_events
    spec.loader.exec_module(module)
    return module


if "cli_events" not in sys.modules:  # bake_process's `import cli_events` outside the package
    _load("cli_events", ROOT / "addon" / "cli_events.py")
bp = _load("cloudgen_bake_process", ROOT / "addon" / "bake_process.py")

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
    params_file = job._temp_files["params"]
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
    assert result.files == want and result.frames == [3, 4, 5], (result.files, result.frames)


def test_last_run_of_hash_is_the_frame_number(tmp_path):
    """`a_##/f_####.vdb`: the CLI numbers the last run; the files come from its plan (the
    add-on's own naming once took the first run and failed this bake)."""
    (tmp_path / "a_##").mkdir()
    result = bp.run_bake(CLI, CUMULUS, 8, str(tmp_path / "a_##" / "f_####.vdb"), frames=(1, 2))
    want = [str(tmp_path / "a_##" / f"f_{f:04d}.vdb") for f in (1, 2)]
    assert result.files == want, result.files
    assert files_in(tmp_path / "a_##") == ["f_0001.vdb", "f_0002.vdb"]
    assert files_in(tmp_path) == ["a_##"]
    no_hash = bp.run_bake(CLI, CUMULUS, 8, str(tmp_path / "x.vdb"), frames=(1, 2))
    assert no_hash.files == [str(tmp_path / "x_0001.vdb"), str(tmp_path / "x_0002.vdb")], no_hash.files


def test_cancel_leaves_no_partial_file(tmp_path):
    out = tmp_path / "big.vdb"
    # large enough to be still running when cancelled; one thread to spare the machine
    job = bp.BakeJob(CLI, CUMULUS, 400, str(out), extra=("--threads", "1", "--no-skip")).start()
    while job.events.fraction == 0.0 and job.poll() is None:
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
    # named as the artist knows it, not as the temporary parameter file nobody has seen
    assert "the cloud's settings: parameter 'density'" in str(err.value), str(err.value)
    assert "cloudgen-params-" not in str(err.value), str(err.value)
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


def _canned(tmp_path, stdout_lines, stderr_line="", code=0):
    """A stand-in CLI that prints fixed lines and exits with code (its `info` succeeds)."""
    exe = tmp_path / "canned"
    exe.write_text(f"""#!{sys.executable}
import sys
if sys.argv[1:2] == ["info"]:
    sys.exit(0)
for line in {stdout_lines!r}:
    print(line)
if {stderr_line!r}:
    print({stderr_line!r}, file=sys.stderr)
sys.exit({code})
""")
    exe.chmod(0o755)
    return exe


def test_error_event_wins_over_stderr(tmp_path):
    exe = _canned(tmp_path, ['{"event": "error", "code": 2, "message": "parameter \'density\' is bad"}'],
                  "cloudgen: error: something else", code=2)
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(exe, CUMULUS, 8, str(tmp_path / "c.vdb"))
    assert err.value.code == bp.BAD_ARGUMENT
    assert str(err.value) == "bad argument: parameter 'density' is bad", str(err.value)


def test_stderr_is_the_fallback_without_an_error_event(tmp_path):
    exe = _canned(tmp_path, [], "cloudgen: error: cannot open x", code=1)
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(exe, CUMULUS, 8, str(tmp_path / "c.vdb"))
    assert err.value.code == bp.IO_ERROR and str(err.value) == "I/O error: cannot open x", str(err.value)


def test_output_outside_the_protocol_fails_the_bake(tmp_path):
    out = tmp_path / "c.vdb"
    out.write_bytes(b"x")
    exe = _canned(tmp_path, ["wrote %s (human output)" % out])
    with pytest.raises(bp.BakeError) as err:
        bp.run_bake(exe, CUMULUS, 8, str(out))
    assert err.value.code == bp.IO_ERROR and "protocol" in str(err.value), str(err.value)


def test_canned_sequence_reports_what_the_events_say(tmp_path):
    paths = [str(tmp_path / f"s_{f:04d}.vdb") for f in (1, 2, 3)]
    for p in paths:
        pathlib.Path(p).write_bytes(b"vdb")
    lines = ['{"event": "plan", "protocol": 1, "files": [%s], "grid": [1, 1, 1], "voxel": 1, '
             '"memory_gib": 0, "threads": 1, "preset": null}'
             % ", ".join('{"frame": %d, "path": "%s"}' % (f, p) for f, p in zip((1, 2, 3), paths)),
             '{"event": "progress", "fraction": 0.5}',
             '{"event": "wrote", "path": "%s", "frame": 1}' % paths[0],
             '{"event": "copied", "path": "%s", "frame": 2, "source": "%s", "source_frame": 1}'
             % (paths[1], paths[0]),
             '{"event": "kept", "path": "%s", "frame": 3}' % paths[2],
             '{"event": "something_new", "x": 1}',
             '{"event": "progress", "fraction": 1.0}']
    seen = []
    result = bp.run_bake(_canned(tmp_path, lines), CUMULUS, 8, str(tmp_path / "s.vdb"), frames=(1, 3),
                         on_progress=seen.append)
    assert result.files == paths and result.frames == [1, 2, 3]
    assert result.paths == paths[:1] and result.copied == [(paths[1], 1)] and result.kept == paths[2:]
    assert result.counts() == "1 baked, 1 copied, 1 kept"
    assert seen == [50.0, 100.0], seen
