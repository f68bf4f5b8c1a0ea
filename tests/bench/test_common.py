"""bench/common.py: atomic writes, marker splicing, machine info (one schema, no
crash when /proc cannot be read), and bench/report.py's use of them."""
import importlib.util
import json
import os
import pathlib
import types

import common
import pytest

BENCH = pathlib.Path(__file__).resolve().parents[2] / "bench"


def bench_report():
    """bench/report.py (a script; `report` is also accuracy.report's name, so load it by path)."""
    spec = importlib.util.spec_from_file_location("bench_report", BENCH / "report.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


# ------------------------------------------------------------ atomic write --


def test_atomic_write_text_bytes_and_mode(tmp_path):
    path = tmp_path / "sub" / "a.txt"
    common.atomic_write(path, "héllo\n")
    assert path.read_bytes() == "héllo\n".encode(), "text is written as UTF-8, folders created"
    assert path.stat().st_mode & 0o777 == 0o644, oct(path.stat().st_mode)
    path.chmod(0o600)
    common.atomic_write(path, b"\x00\x01")
    assert path.read_bytes() == b"\x00\x01" and path.stat().st_mode & 0o777 == 0o600, "a replaced file keeps its mode"
    common.write_json(tmp_path / "b.json", {"a": [1]})
    assert (tmp_path / "b.json").read_text() == '{\n "a": [\n  1\n ]\n}\n'
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.txt", "b.json", "sub"], "no temporary files"


@pytest.mark.parametrize("fail", ["write", "replace"])
def test_atomic_write_error_keeps_old_file_and_leaves_no_temp(tmp_path, monkeypatch, fail):
    path = tmp_path / "results.json"
    path.write_text("old")
    if fail == "write":
        data = 12345  # not str / bytes: the write fails after the temporary file exists
        expect = TypeError
    else:
        data = "new"
        expect = OSError

        def broken_replace(src, dst):
            assert pathlib.Path(src).exists(), "the temporary file exists when os.replace runs"
            raise OSError("disk full")

        monkeypatch.setattr(common.os, "replace", broken_replace)
    with pytest.raises(expect):
        common.atomic_write(path, data)
    assert path.read_text() == "old", "the old file is untouched"
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"], "the temporary file is removed"


# ------------------------------------------------------------------ splice --

B, E = "<!-- begin -->", "<!-- end -->"


def test_splice_replaces_only_the_block():
    doc = f"# T\n\nbefore\n\n{B}\nold\nlines\n{E}\n\nafter\n"
    new = common.splice(doc, B, E, "NEW")
    assert new == f"# T\n\nbefore\n\n{B}\nNEW\n{E}\n\nafter\n", repr(new)
    assert common.splice(new, B, E, "NEW") == new, "idempotent"
    blank = common.splice(doc, B, E, "\nwith blank lines\n")
    assert blank == f"# T\n\nbefore\n\n{B}\n\nwith blank lines\n\n{E}\n\nafter\n"


def test_splice_without_markers_appends_or_creates():
    assert common.splice("hand  \n\n", B, E, "G") == f"hand\n\n{B}\nG\n{E}\n"
    assert common.splice("", B, E, "G", new_doc="# New\n\n") == f"# New\n\n{B}\nG\n{E}\n"
    assert common.splice(" \n", B, E, "G") == f"{B}\nG\n{E}\n"
    swapped = f"x\n{E}\n{B}\n"  # markers in the wrong order are not a block
    assert common.splice(swapped, B, E, "G") == f"{swapped.rstrip()}\n\n{B}\nG\n{E}\n"


def test_report_render_writes_block_atomically(tmp_path, monkeypatch):
    rep = bench_report()
    monkeypatch.setattr(rep, "render_generated", lambda results: "\nTABLES\n")
    doc = tmp_path / "benchmarks.md"
    doc.write_text(f"# B\n\n{rep.BEGIN}\nstale\n{rep.END}\n\ntail\n")
    rep.cmd_render(types.SimpleNamespace(doc=str(doc), results=str(tmp_path)))
    assert doc.read_text() == f"# B\n\n{rep.BEGIN}\n\nTABLES\n\n{rep.END}\n\ntail\n"
    new = tmp_path / "new.md"
    rep.cmd_render(types.SimpleNamespace(doc=str(new), results=str(tmp_path)))
    assert new.read_text() == f"# Benchmarks\n\n{rep.BEGIN}\n\nTABLES\n\n{rep.END}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["benchmarks.md", "new.md"]


# ----------------------------------------------------------------- machine --

CPUINFO = """processor\t: 0
vendor_id\t: GenuineIntel
cpu family\t: 6
model\t\t: 167
model name\t: Test CPU @ 2.60GHz
stepping\t: 1
cpu MHz\t\t: 2599.998
flags\t\t: fpu sse4_2 avx avx2 fma hypervisor
"""
MEMINFO = "MemTotal:       24641536 kB\nMemFree:        1000 kB\n"
KEYS = ["cpu_model", "cpu_vendor", "cpu_family_model_stepping", "cpu_mhz_nominal", "simd", "hypervisor", "nproc",
        "mem_total_gib", "kernel", "load_average"]


def test_machine_info_parses_proc():
    files = {"/proc/cpuinfo": CPUINFO, "/proc/meminfo": MEMINFO}
    m = common.machine_info(read=lambda path: files[path])
    assert list(m) == KEYS, "one schema"
    assert (m["cpu_model"], m["cpu_vendor"], m["cpu_family_model_stepping"]) == ("Test CPU @ 2.60GHz",
                                                                                  "GenuineIntel", "6/167/1"), m
    assert m["cpu_mhz_nominal"] == 2599.998 and m["simd"] == ["sse4_2", "avx", "avx2", "fma"] and m["hypervisor"]
    assert m["mem_total_gib"] == 23.5, m
    assert m["nproc"] >= 1 and len(m["load_average"]) == 3
    json.dumps(m)


@pytest.mark.parametrize("unreadable", ["/proc/cpuinfo", "/proc/meminfo", "both"])
def test_machine_info_with_unreadable_proc(monkeypatch, unreadable):
    files = {"/proc/cpuinfo": CPUINFO, "/proc/meminfo": MEMINFO}

    def read(path):  # what common.read_text returns for a file it cannot open
        return "" if unreadable in (path, "both") else files[path]

    monkeypatch.setattr(common, "read_text", read)  # the default reader, as bench/report.py calls it
    m = common.machine_info()
    assert list(m) == KEYS, "the same schema when /proc cannot be read"
    if unreadable != "/proc/cpuinfo":
        assert m["mem_total_gib"] is None
    if unreadable != "/proc/meminfo":
        assert m["cpu_vendor"] == "" and m["cpu_mhz_nominal"] is None and m["simd"] == [] and not m["hypervisor"]
    json.dumps(m)


def test_read_text_of_an_unreadable_file_is_empty(tmp_path, monkeypatch):
    assert common.read_text(tmp_path / "missing") == ""

    def denied(*args, **kwargs):
        raise PermissionError("denied")

    monkeypatch.setattr("builtins.open", denied)
    assert common.read_text("/proc/meminfo") == ""
    m = common.machine_info()
    assert m["mem_total_gib"] is None and m["cpu_vendor"] == ""


def test_report_machine_and_its_table_without_proc(tmp_path, monkeypatch):
    rep = bench_report()
    monkeypatch.setattr(common, "read_text", lambda path: "")
    out = tmp_path / "machine.json"
    rep.cmd_machine(types.SimpleNamespace(out=str(out), build=str(tmp_path)))
    m = json.loads(out.read_text())
    assert list(m)[1:len(KEYS) + 1] == KEYS and m["mem_total_gib"] is None, m
    table = rep.render_machine(m, None)
    assert "| Memory | unknown |" in table and "nominal" not in table, table
    assert os.listdir(tmp_path) == ["machine.json"]
