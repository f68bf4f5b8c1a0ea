"""Sequence bakes that copy or keep unchanged frames (`--frames`, `--sequence`, `--update`):
frames with equal bake keys are byte copies, --update keeps files whose stored key matches.
Exact checks (file names, bytes, events)."""
import json

import pytest
from cli_bake_helpers import (
    bake_keys,
    grid,
    run,
)
from test_cli import cli_events, events, expect_usage_error, listing

# -------------------------------------------------------------- sequences ---

STILL = {"preset": "cumulus", "evolution": 0, "wind_strength": 0}


def lines_of(result, verb):
    """The `verb` events (wrote, copied, kept) of a --json bake, as (path, source frame or None)."""
    ev = events(result)
    chosen = {"wrote": ev.written, "copied": ev.copied, "kept": ev.kept}[verb]
    return [(e["path"], e.get("source_frame")) for e in chosen]


def test_still_cloud_frames_are_copied_then_kept(inputs, out_dir):
    params = inputs(STILL, "still.json")
    pattern = out_dir / "s.vdb"
    args = ("bake", "--params", params, "--frames", "1-4", "--resolution", 16, "--output", pattern)
    r = run(*args)
    assert r.returncode == 0, (r.stdout, r.stderr)
    names = [f"s_{n:04d}.vdb" for n in range(1, 5)]
    assert listing(out_dir) == names
    assert lines_of(r, "wrote") == [(str(out_dir / names[0]), None)], r.stdout
    assert len(lines_of(r, "wrote")) == 1, r.stdout
    assert lines_of(r, "copied") == [(str(out_dir / n), 1) for n in names[1:]], r.stdout
    data = [(out_dir / n).read_bytes() for n in names]
    assert all(d == data[0] for d in data), "copied frames are byte-identical to frame 1"

    # --update: every stored bake key matches -> all kept, files untouched (exact bytes).
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert lines_of(r, "kept") == [(str(out_dir / n), None) for n in names], r.stdout
    assert not lines_of(r, "wrote") and not lines_of(r, "copied"), r.stdout
    assert [(out_dir / n).read_bytes() for n in names] == data

    # A deleted frame comes back as a copy of a kept one.
    (out_dir / names[2]).unlink()
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "kept")) == 3, r.stdout
    assert lines_of(r, "copied") == [(str(out_dir / names[2]), 1)], r.stdout
    assert (out_dir / names[2]).read_bytes() == data[0]

    # Change the density: the stored keys no longer match -> baked again, not kept.
    params.write_text(json.dumps({**STILL, "density": 0.3}))
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert not lines_of(r, "kept"), r.stdout
    assert len(lines_of(r, "wrote")) == 1 and len(lines_of(r, "copied")) == 3, r.stdout
    stored = json.loads(grid(out_dir / names[0])["metadata"]["cloudgen_params"])["density"]
    assert stored == pytest.approx(0.3, rel=1e-6), stored  # float32 round trip
    assert all((out_dir / n).read_bytes() == (out_dir / names[0]).read_bytes() for n in names[1:])


def test_evolving_cloud_frames_are_all_baked(out_dir):
    pattern = out_dir / "e.vdb"
    args = ("bake", "--preset", "cumulus", "--frames", "1-4", "--resolution", 16, "--output", pattern)
    r = run(*args)  # cumulus: evolution 0.1, so time changes the field
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "wrote")) == 4 and not lines_of(r, "copied"), r.stdout
    keys = bake_keys([out_dir / f"e_{n:04d}.vdb" for n in range(1, 5)])
    assert len(set(keys)) == 4, keys
    r = run(*args, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "kept")) == 4 and not lines_of(r, "wrote"), r.stdout
    # Another resolution is another bake: --update re-bakes every frame.
    r = run("bake", "--preset", "cumulus", "--frames", "1-4", "--resolution", 20, "--output", pattern, "--update")
    assert r.returncode == 0, r.stderr
    assert len(lines_of(r, "wrote")) == 4 and not lines_of(r, "kept"), r.stdout


def test_update_rebakes_an_unreadable_file(out_dir):
    out = out_dir / "x.vdb"
    out.write_text("not a vdb")
    r = run("bake", "--preset", "cumulus", "--resolution", 16, "--output", out, "--update", "--quiet")
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert lines_of(r, "wrote"), r.stdout
    assert grid(out)["active_voxels"] > 0


def test_sequence_file_per_frame_params(inputs, out_dir):
    seq = {"fps": 24, "frames": [
        {"frame": 1, "params": {"preset": "cumulus", "density": 0.4}},
        {"frame": 2, "params": {"preset": "cumulus", "density": 0.4}},
        {"frame": 3, "params": {"preset": "cumulus", "density": 0.6}}]}
    r = run("bake", "--sequence", inputs(seq, "seq.json"), "--resolution", 16, "--output", out_dir / "q_##.vdb")
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert listing(out_dir) == ["q_01.vdb", "q_02.vdb", "q_03.vdb"]
    verbs = [(e["event"], e["path"], e.get("source_frame"))
             for e in map(cli_events.parse, r.stdout.splitlines()) if e["event"] in ("wrote", "copied", "kept")]
    assert verbs == [("wrote", str(out_dir / "q_01.vdb"), None), ("copied", str(out_dir / "q_02.vdb"), 1),
                     ("wrote", str(out_dir / "q_03.vdb"), None)], r.stdout
    for name, density in (("q_01.vdb", 0.4), ("q_02.vdb", 0.4), ("q_03.vdb", 0.6)):
        stored = json.loads(grid(out_dir / name)["metadata"]["cloudgen_params"])["density"]
        assert stored == pytest.approx(density, rel=1e-6), (name, stored)  # float32 round trip


BAD_SEQUENCES = [
    ("duplicate frame", {"frames": [{"frame": 1, "params": {}}, {"frame": 1, "params": {}}]},
     ["--sequence", "frame 1", "twice"]),
    ("missing params", {"frames": [{"frame": 1}]}, ["--sequence", "params"]),
    ("unknown key", {"frames": [{"frame": 1, "params": {}}], "fsp": 24}, ["--sequence", "fsp"]),
    ("bad param", {"frames": [{"frame": 1, "params": {"densty": 1}}]}, ["--sequence", "densty"]),
    ("bad JSON", '{"frames": [', ["--sequence", "JSON"]),
]


@pytest.mark.parametrize("case,content,words", BAD_SEQUENCES, ids=[c[0] for c in BAD_SEQUENCES])
def test_bad_sequence_files(case, content, words, inputs, out_dir):
    r = run("bake", "--sequence", inputs(content, "seq.json"), "--resolution", 16, "--output", out_dir / "x.vdb")
    expect_usage_error(r, *words)
    assert listing(out_dir) == []


@pytest.mark.parametrize("extra", [["--preset", "cumulus"], ["--frames", "1-2"]], ids=["preset", "frames"])
def test_sequence_excludes_other_sources(extra, inputs, out_dir):
    seq = inputs({"frames": [{"frame": 1, "params": {}}]}, "seq.json")
    r = run("bake", "--sequence", seq, *extra, "--resolution", 16, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--sequence", extra[0])
    assert listing(out_dir) == []


