"""The CLI's machine-readable output (docs/cli_protocol.md) and the one frame-naming
function shared by the CLI and the module (cloudgen_native.frame_path).

Exact checks (no tolerances): the protocol is text, file names are strings.
"""
import json

import cloudgen_native as cn
import pytest
from test_cli import REPO_ROOT, cli_events, events, listing, run


def test_version_names_the_protocol_and_matches_the_module():
    human = run("--version")
    assert human.returncode == 0 and human.stdout.strip().endswith("(protocol 1)"), human.stdout
    info = json.loads(run("--version", "--json").stdout)
    assert info == {"version": cn.version()["version"], "protocol": cli_events.PROTOCOL}, info
    assert cn.version()["protocol"] == cli_events.PROTOCOL
    cli_events.check_protocol(info, cn.version())  # same release, same protocol: no error
    with pytest.raises(cli_events.ProtocolError, match="different releases"):
        cli_events.check_protocol(info, {"version": "0.0.0-other", "protocol": 1})
    with pytest.raises(cli_events.ProtocolError, match="protocol 99"):
        cli_events.check_protocol({**info, "protocol": 99})
    assert run("--version", "--bogus").returncode == 2


def test_sequence_events_in_order(out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 12, "--frames", "3-4", "--json",
            "--output", out_dir / "c_####.vdb")
    assert r.returncode == 0, r.stderr
    kinds = [json.loads(line)["event"] for line in r.stdout.splitlines()]
    assert kinds[0] == "plan" and kinds.count("wrote") == 2 and "error" not in kinds, kinds
    assert kinds.index("frame") < kinds.index("progress") < kinds.index("wrote"), kinds
    ev = events(r)
    want = [str(out_dir / "c_0003.vdb"), str(out_dir / "c_0004.vdb")]
    assert ev.files == want and [e["path"] for e in ev.written] == want
    assert [e["frame"] for e in ev.written] == [3, 4]
    assert ev.fraction == 1.0 and not ev.unknown
    for e in ev.written:
        assert e["active_voxels"] > 0 and e["bytes"] > 0 and e["grid"] == ev.plan["grid"], e
    assert r.stderr == "", "JSON mode: nothing on stderr unless there is an error"


def test_single_bake_frame_is_null(out_dir):
    r = run("bake", "--preset", "stratus", "--resolution", 8, "--json", "--output", out_dir / "s.vdb")
    ev = events(r)
    assert ev.plan["files"] == [{"frame": None, "path": str(out_dir / "s.vdb"), "key": ev.written[0]["key"]}]
    assert ev.written[0]["frame"] is None and ev.plan["preset"] == "stratus"


def test_error_is_the_last_event_and_one_stderr_line(out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 0, "--json", "--output", out_dir / "x.vdb")
    assert r.returncode == 2
    ev = events(r)
    assert ev.error == {"event": "error", "code": 2, "message": ev.error["message"]}
    assert "--resolution" in ev.error["message"] and "[1, 1000000]" in ev.error["message"], ev.error
    assert r.stderr.strip().splitlines() == [f"cloudgen: error: {ev.error['message']}"]
    assert listing(out_dir) == []


def test_quiet_json_has_no_progress(out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 12, "--json", "--quiet", "--output", out_dir / "q.vdb")
    kinds = [json.loads(line)["event"] for line in r.stdout.splitlines()]
    assert kinds == ["plan", "wrote"], kinds


def test_preview_json(out_dir):
    r = run("preview", "--preset", "cumulus", "--axis", "y", "--size", 32, "--json", "--output", out_dir / "p.png")
    assert r.returncode == 0, r.stderr
    (line,) = r.stdout.splitlines()
    e = cli_events.parse(line)
    box = json.loads((REPO_ROOT / "native" / "presets" / "clouds.json").read_text())["cumulus"]["params"]["box_size"]
    height = round(32 * box[2] / box[0])  # the box face's aspect (x, z) for axis y
    assert e["event"] == "wrote" and e["path"] == str(out_dir / "p.png") and e["size"] == [32, height], e
    # the PNG's display scale: auto = max(peak/3, 0.001) (tolerance: float32 rounding)
    assert e["png_scale"] == pytest.approx(max(0.001, e["max_density"] / 3.0), rel=1e-6), e


@pytest.mark.parametrize("args,expected", [(["--png-scale", "2.5"], 2.5), (["--png-scale", "auto"], None)])
def test_preview_json_png_scale(args, expected, out_dir):
    r = run("preview", "--preset", "stratus", "--axis", "z", "--size", 16, "--json", *args,
            "--output", out_dir / "p.png")
    assert r.returncode == 0, r.stderr
    e = cli_events.parse(r.stdout.splitlines()[0])
    want = expected if expected is not None else max(0.001, e["max_density"] / 3.0)
    assert e["png_scale"] == pytest.approx(want, rel=1e-6), (args, e)
    r = run("preview", "--preset", "stratus", "--axis", "z", "--size", 16, "--json", "--output", out_dir / "p.exr")
    assert cli_events.parse(r.stdout.splitlines()[0])["png_scale"] is None, "an EXR holds densities, no scale"


# The naming rule (docs/cli_protocol.md): the LAST run of '#' is the zero-padded frame.
FRAME_NAMES = [
    ("a_##/f_####.vdb", 7, "a_##/f_0007.vdb"),   # the add-on once used the first run here
    ("f_##.vdb", 12345, "f_12345.vdb"),           # a longer number is written whole
    ("f_###.vdb", -7, "f_-007.vdb"),
    ("cloud.vdb", 3, "cloud_0003.vdb"),
    ("dir.d/cloud", 3, "dir.d/cloud_0003"),       # a dot in a folder is not an extension
    ("#" * 40 + ".vdb", 5, "0" * 39 + "5.vdb"),   # any run length (was a 32-byte buffer)
]


@pytest.mark.parametrize("pattern,frame,expect", FRAME_NAMES)
def test_module_frame_path(pattern, frame, expect):
    assert cn.frame_path(pattern, frame) == expect, (pattern, frame)


def test_cli_names_files_as_the_module_does(out_dir):
    (out_dir / "a_##").mkdir()
    pattern = str(out_dir / "a_##" / ("#" * 33 + ".vdb"))
    r = run("bake", "--preset", "cumulus", "--resolution", 8, "--frames", "1-3", "--json", "--output", pattern)
    assert r.returncode == 0, r.stderr
    ev = events(r)
    want = [cn.frame_path(pattern, f) for f in (1, 2, 3)]
    assert ev.files == want == [e["path"] for e in ev.written], (ev.files, want)
    assert len(set(want)) == 3 and listing(out_dir / "a_##") == sorted(p.split("/")[-1] for p in want)


@pytest.mark.parametrize("bad", [("x.vdb", 1.5), (3, 1), ("x.vdb", 10**7), ("x" * 5000, 1)])
def test_module_frame_path_refuses(bad):
    with pytest.raises((TypeError, ValueError)):
        cn.frame_path(*bad)


def test_reader_refuses_non_protocol_lines():
    ev = cli_events.BakeEvents()
    assert ev.feed("") is None
    with pytest.raises(cli_events.ProtocolError):
        ev.feed("bake: 10%")
    with pytest.raises(cli_events.ProtocolError):
        ev.feed('{"no_event": 1}')
    with pytest.raises(cli_events.ProtocolError, match="protocol 2"):
        ev.feed('{"event": "plan", "protocol": 2, "files": []}')
    ev.feed('{"event": "something_new", "x": 1}')
    assert ev.unknown == [{"event": "something_new", "x": 1}]


def test_threads_follow_cpu_affinity(out_dir):
    """--threads 0 means one per core this process may use (taskset, cpusets), not per machine core."""
    import os
    import subprocess

    from test_cli import CLOUDGEN

    cores = sorted(os.sched_getaffinity(0))
    args = ["bake", "--preset", "cumulus", "--resolution", "8", "--dry-run", "--json", "--output",
            str(out_dir / "t.vdb")]
    pinned = subprocess.run([CLOUDGEN, *args], capture_output=True, text=True, timeout=60,
                            preexec_fn=lambda: os.sched_setaffinity(0, {cores[0]}))
    free = run(*args)
    assert json.loads(pinned.stdout.splitlines()[0])["threads"] == 1, pinned.stdout
    assert json.loads(free.stdout.splitlines()[0])["threads"] == len(cores), free.stdout
