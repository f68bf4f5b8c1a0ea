"""Run `cloudgen bake --json` as a subprocess: progress, cancel, errors. No bpy here,
so this module is tested with plain pytest (tests/addon_bake/test_bake_process.py).

    job = BakeJob(cloudgen, params, resolution=64, output="clouds/c.vdb")
    job.start()
    while job.poll() is None:      # non-blocking; job.progress is 0..100
        ...
    result = job.poll()            # BakeResult: ok, code, message, files, paths, copied, kept

or `run_bake(...)` for a blocking bake that raises BakeError.

The CLI's protocol (docs/cli_protocol.md), read by cli_events.BakeEvents: one JSON
event per stdout line. The `plan` event names every file the run writes (the
CLI alone names files: for a sequence the LAST run of '#' in --output is the
frame number); `progress`, and per file `wrote`, `copied` (with its source) or
`kept`; a failed run ends with an `error` event (code, message) and also prints
`cloudgen: error: ...` on stderr, the fallback when no event came. Exit 0 ok,
1 I/O failure, 2 bad argument, 130 cancelled; files are written atomically (an
error or SIGTERM leaves no partial file; finished frames stay).

Defence in depth: a full disk can go unnoticed by OpenVDB's stream writer
(the CLI then exits 0 with a truncated file), so after a successful bake every
written file is read back with `cloudgen info` (a copy of a frame: its size is
compared with the source's; a kept file was checked when it was written); a
file that does not read is deleted and the bake fails with exit code 1.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import tempfile
import threading
from dataclasses import dataclass, field

try:
    from . import cli_events
except ImportError:  # loaded by its path (tests/addon_bake/test_bake_process.py loads cli_events first)
    import cli_events

OK, IO_ERROR, BAD_ARGUMENT, CANCELLED = 0, 1, 2, 130
_KIND = {IO_ERROR: "I/O error", BAD_ARGUMENT: "bad argument", CANCELLED: "cancelled"}
_TEMP_SOURCES = {"params": "the cloud's settings", "sequence": "the cloud's keyframed settings",
                 "camera": "the Fit to Camera data"}


@dataclass
class BakeResult:
    code: int
    message: str = ""
    paths: list = field(default_factory=list)    # baked (`wrote` events' paths)
    copied: list = field(default_factory=list)   # (path, frame it repeats) (`copied`)
    kept: list = field(default_factory=list)     # unchanged outputs left as they were (`kept`)
    files: list = field(default_factory=list)    # every output, in frame order (the `plan`)
    frames: list = field(default_factory=list)   # their frame numbers (None for a single bake)

    def counts(self) -> str:
        """'3 baked, 2 copied, 0 kept'"""
        return f"{len(self.paths)} baked, {len(self.copied)} copied, {len(self.kept)} kept"

    @property
    def ok(self) -> bool:
        return self.code == OK

    @property
    def cancelled(self) -> bool:
        return self.code == CANCELLED


class BakeError(RuntimeError):
    def __init__(self, result: BakeResult):
        super().__init__(result.message)
        self.result = result
        self.code = result.code


def bake_command(executable, params_file, resolution, output, frames=None, fps=24.0, extra=(),
                 sequence_file=None):
    """The CLI's argument list. resolution None: none given (the --quality tier's);
    sequence_file: per-frame parameters (--sequence) instead of --params/--frames."""
    cmd = [str(executable), "bake", "--json"]
    if sequence_file is not None:
        cmd += ["--sequence", str(sequence_file)]
    else:
        cmd += ["--params", str(params_file)]
    if resolution is not None:
        cmd += ["--resolution", str(int(resolution))]
    cmd += ["--output", str(output)]
    if frames is not None and sequence_file is None:
        a, b = frames
        cmd += ["--frames", f"{int(a)}-{int(b)}", "--fps", repr(float(fps))]
    return cmd + [str(x) for x in extra]


class BakeJob:
    """One `cloudgen bake --json` run. Thread-safe reads of progress and events; poll() never blocks."""

    def __init__(self, executable, params: dict, resolution, output: str,
                 frames=None, fps: float = 24.0, extra=(), verify: bool = True, on_progress=None,
                 sequence=None, camera=None):
        """resolution: int, or None to leave it to `--quality` in extra; frames: (first, last)
        bakes a frame range of params (--frames); sequence: the --sequence object ({"fps",
        "frames": [{"frame", "params"}]}) instead of params; camera: the CAMERA.json object
        (--camera). The parameter, sequence and camera files are temporary, removed when
        the bake ends."""
        if not executable:
            raise BakeError(BakeResult(BAD_ARGUMENT, "the cloudgen command-line tool was not found "
                                                     "(not in the add-on's bin/ nor on PATH)"))
        self.executable = str(executable)
        self.params = dict(params)
        self.resolution = None if resolution is None else int(resolution)
        self.output = str(output)
        self.frames = frames
        self.fps = fps
        self.extra = tuple(extra)
        self.verify = verify
        self.on_progress = on_progress
        self.events = cli_events.BakeEvents()
        self.stdout_lines: list = []
        self.stderr_lines: list = []
        self.protocol_error = None   # the first line that broke the protocol
        self.sequence = sequence
        self.camera = camera
        self._proc = None
        self._temp_files: dict = {}
        self._temp_names: dict = {}  # kind -> path, kept after the files are removed (messages)
        self._threads: list = []
        self._cancel_requested = False
        self._result = None
        self._lock = threading.Lock()

    @property
    def progress(self) -> float:
        """0..100 over the whole run."""
        return 100.0 if self._result is not None and self._result.ok else 100.0 * self.events.fraction

    # -- running ---------------------------------------------------------
    def command(self):
        extra = list(self.extra)
        if self.camera is not None:
            extra += ["--camera", self._temp_files.get("camera", "CAMERA.json")]
        sequence_file = None
        if self.sequence is not None:
            sequence_file = self._temp_files.get("sequence", "SEQUENCE.json")
        return bake_command(self.executable, self._temp_files.get("params", "PARAMS.json"), self.resolution,
                            self.output, self.frames, self.fps, extra, sequence_file)

    def _write_temp(self, kind, data):
        fd, path = tempfile.mkstemp(prefix=f"cloudgen-{kind}-", suffix=".json")
        self._temp_files[kind] = path
        self._temp_names[kind] = path
        with os.fdopen(fd, "w") as f:
            json.dump(data, f)
        return path

    def start(self):
        if self.sequence is not None:
            self._write_temp("sequence", self.sequence)
        else:
            self._write_temp("params", self.params)
        if self.camera is not None:
            self._write_temp("camera", self.camera)
        try:
            self._proc = subprocess.Popen(
                self.command(), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                stderr=subprocess.PIPE, text=True, bufsize=1, errors="replace")
        except OSError as exc:
            self._cleanup()
            raise BakeError(BakeResult(BAD_ARGUMENT, f"cannot run {self.executable}: {exc}")) from exc
        for stream, sink in ((self._proc.stdout, self._on_stdout), (self._proc.stderr, self._on_stderr)):
            t = threading.Thread(target=self._pump, args=(stream, sink), daemon=True)
            t.start()
            self._threads.append(t)
        return self

    def _pump(self, stream, sink):
        for line in stream:
            sink(line.rstrip("\n"))
        stream.close()

    def _on_stdout(self, line):
        with self._lock:
            self.stdout_lines.append(line)
            before = self.events.fraction
            try:
                event = self.events.feed(line)
            except cli_events.ProtocolError as exc:
                event = None
                if self.protocol_error is None:
                    self.protocol_error = str(exc)
            moved = self.events.fraction != before
        if event is not None and moved and self.on_progress is not None:
            self.on_progress(100.0 * self.events.fraction)

    def _on_stderr(self, line):
        with self._lock:
            self.stderr_lines.append(line)

    def cancel(self):
        """Ask the CLI to stop (SIGTERM: it removes its temporary file, exits 130)."""
        self._cancel_requested = True
        if self._proc is not None and self._proc.poll() is None:
            try:
                self._proc.send_signal(signal.SIGTERM)
            except ProcessLookupError:
                pass

    def poll(self):
        """None while running, else the BakeResult (computed once)."""
        if self._result is not None:
            return self._result
        if self._proc is None or self._proc.poll() is None:
            return None
        return self._finish()

    def wait(self, timeout=None):
        """Block until the CLI exits; return the BakeResult."""
        if self._result is None:
            self._proc.wait(timeout=timeout)
            self._finish()
        return self._result

    def _finish(self):
        for t in self._threads:
            t.join()
        code = self._proc.returncode
        self._cleanup()
        if code < 0:  # killed by a signal other than the ones it handles
            code = CANCELLED if self._cancel_requested else IO_ERROR
        ev = self.events
        plan = (ev.plan or {}).get("files", [])
        result = BakeResult(code, "", [e["path"] for e in ev.written],
                            [(e["path"], e.get("source_frame")) for e in ev.copied],
                            [e["path"] for e in ev.kept], [f["path"] for f in plan],
                            [f.get("frame") for f in plan])
        if code == OK and (self.protocol_error or ev.plan is None):
            result.code = IO_ERROR
            result.message = ("I/O error: the cloudgen command-line tool broke its output protocol "
                              f"(docs/cli_protocol.md): {self.protocol_error or 'no plan event'}")
        else:
            result.message = self._message(code, result)
        if result.ok:
            result = self._verified(result)
        self._result = result
        if result.ok and self.on_progress is not None and ev.fraction < 1.0:
            self.on_progress(100.0)
        return result

    def _message(self, code, result):
        if code == OK:
            if result.copied or result.kept:
                return (f"{result.counts()} ({len(result.paths) + len(result.copied) + len(result.kept)} files)")
            return f"baked {len(result.paths)} file(s): " + ", ".join(result.paths)
        if code == CANCELLED:
            return "bake cancelled; no partial file left" + (
                f" ({len(result.paths)} finished frame(s) kept)" if result.paths else "")
        error = self.events.error
        if error is not None and str(error.get("message", "")).strip():
            text = str(error["message"]).strip()
        else:  # no error event (a crash, a protocol problem): the stderr line
            errors = [ln for ln in self.stderr_lines if ln.strip()]
            text = errors[-1] if errors else f"cloudgen bake exited with code {code}"
            text = re.sub(r"^cloudgen: (error: )?", "", text)
        # The CLI names the file a value came from; ours are temporary files nobody
        # has seen: say whose values they are instead.
        for kind, path in self._temp_names.items():
            text = text.replace(f"--{kind} {path}", _TEMP_SOURCES.get(kind, f"the {kind} file"))
        return f"{_KIND.get(code, 'error')}: {text}"

    def _verified(self, result):
        expected = result.files
        missing = [p for p in expected if not os.path.isfile(p)]
        if missing:
            result.code = IO_ERROR
            result.message = f"I/O error: cloudgen reported success but {missing[0]} does not exist"
            return result
        if not self.verify:
            return result
        kept = {os.path.normpath(k) for k in result.kept}  # untouched: read back when written
        sources = {os.path.normpath(e["path"]): e.get("source") for e in self.events.copied}
        for path in expected:
            if os.path.normpath(path) in kept:
                continue
            if _same_size(path, sources.get(os.path.normpath(path))):
                continue  # a whole copy of a file that is read back itself
            check = subprocess.run([self.executable, "info", path], stdin=subprocess.DEVNULL,
                                   capture_output=True, text=True, errors="replace")
            if check.returncode != 0:
                for p in expected:  # a truncated file must not stay behind
                    try:
                        os.remove(p)
                    except OSError:
                        pass
                why = (check.stderr.strip().splitlines() or ["unreadable"])[-1]
                why = re.sub(r"^cloudgen: (error: )?", "", why)
                return BakeResult(IO_ERROR, f"I/O error: {path} was written but does not read back "
                                            f"(disk full?): {why}; removed", [], [], [], list(result.files),
                                  list(result.frames))
        return result

    def _cleanup(self):
        for path in self._temp_files.values():
            try:
                os.remove(path)
            except OSError:
                pass
        self._temp_files.clear()


def _same_size(path, source) -> bool:
    """path is a copy (`copied` event) of source and has its size."""
    if not source:
        return False
    try:
        return os.path.getsize(path) == os.path.getsize(source) > 0
    except OSError:
        return False


def run_bake(executable, params: dict, resolution: int, output: str, frames=None, fps=24.0,
             extra=(), on_progress=None, verify=True) -> BakeResult:
    """Blocking bake; BakeError (with .code and the CLI's one-line message) on failure."""
    job = BakeJob(executable, params, resolution, output, frames, fps, extra, verify, on_progress)
    job.start()
    try:
        result = job.wait()
    except BaseException:  # KeyboardInterrupt while waiting: stop the CLI, then re-raise
        job.cancel()
        job.wait()
        raise
    if not result.ok:
        raise BakeError(result)
    return result
