"""Run `cloudgen bake` as a subprocess: progress, cancel, errors. No bpy here,
so this module is tested with plain pytest (tests/addon_bake/test_bake_process.py).

    job = BakeJob(cloudgen, params, resolution=64, output="/tmp/c.vdb")
    job.start()
    while job.poll() is None:      # non-blocking; job.progress is 0..100
        ...
    result = job.poll()            # BakeResult: ok, code, message, paths

or `run_bake(...)` for a blocking bake that raises BakeError.

The CLI's contract (`cloudgen bake --help`): `bake: P%` lines on stdout, one
`wrote PATH ...`, `copied PATH (same field as frame N)` or `kept PATH (unchanged)`
line per file (BakeResult.paths / .copied / .kept), a one-line
`cloudgen: error: ...` on stderr, exit 0 ok / 1 I/O failure / 2 bad argument / 130 cancelled, files written
atomically (an error or SIGTERM leaves no partial file; finished frames stay).

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

OK, IO_ERROR, BAD_ARGUMENT, CANCELLED = 0, 1, 2, 130
_PROGRESS = re.compile(r"^bake: (\d+(?:\.\d+)?)%\s*$")
_WROTE = re.compile(r"^wrote (.+?) \(")
_COPIED = re.compile(r"^copied (.+?) \(same field as frame (-?\d+)\)")
_KEPT = re.compile(r"^kept (.+?) \(unchanged\)")
_KIND = {IO_ERROR: "I/O error", BAD_ARGUMENT: "bad argument", CANCELLED: "cancelled"}


@dataclass
class BakeResult:
    code: int
    message: str = ""
    paths: list = field(default_factory=list)    # baked (`wrote`)
    copied: list = field(default_factory=list)   # (path, frame it repeats) (`copied`)
    kept: list = field(default_factory=list)     # unchanged outputs left as they were (`kept`)

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


def sequence_paths(output: str, first: int, last: int) -> list:
    """The files a sequence bake writes, as the CLI names them: a run of '#' is
    the zero-padded frame number, else _0001 goes before the extension."""
    m = re.search(r"#+", output)
    out = []
    for f in range(first, last + 1):
        if m:
            out.append(output[:m.start()] + str(f).zfill(len(m.group())) + output[m.end():])
        else:
            stem, ext = os.path.splitext(output)
            out.append(f"{stem}_{f:04d}{ext or '.vdb'}")
    return out


def bake_command(executable, params_file, resolution, output, frames=None, fps=24.0, extra=(),
                 sequence_file=None):
    """The CLI's argument list. resolution None: none given (the --quality tier's);
    sequence_file: per-frame parameters (--sequence) instead of --params/--frames."""
    cmd = [str(executable), "bake"]
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
    """One `cloudgen bake` run. Thread-safe reads of progress/lines; poll() never blocks."""

    def __init__(self, executable, params: dict, resolution, output: str,
                 frames=None, fps: float = 24.0, extra=(), verify: bool = True, on_progress=None,
                 sequence=None, camera=None):
        """resolution: int, or None to leave it to `--quality` in extra; sequence: the
        --sequence object ({"fps", "frames": [{"frame", "params"}]}; frames = (first, last)
        names the files); camera: the CAMERA.json object (--camera). Both are written to
        temporary files that are removed when the bake ends."""
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
        self.progress = 0.0
        self.stdout_lines: list = []
        self.stderr_lines: list = []
        self.written: list = []
        self.copied: list = []
        self.kept: list = []
        self.sequence = sequence
        self.camera = camera
        self._proc = None
        self._params_file = None
        self._temp_files: list = []
        self._threads: list = []
        self._cancel_requested = False
        self._result = None
        self._lock = threading.Lock()

    # -- running ---------------------------------------------------------
    def command(self):
        extra = list(self.extra)
        if self.camera is not None:
            extra += ["--camera", self._temp("camera") or "CAMERA.json"]
        sequence_file = None
        if self.sequence is not None:
            sequence_file = self._temp("sequence") or "SEQUENCE.json"
        return bake_command(self.executable, self._params_file or "PARAMS.json", self.resolution,
                            self.output, self.frames, self.fps, extra, sequence_file)

    def _temp(self, kind):
        for k, path in self._temp_files:
            if k == kind:
                return path
        return None

    def _write_temp(self, kind, data):
        fd, path = tempfile.mkstemp(prefix=f"cloudgen-{kind}-", suffix=".json")
        self._temp_files.append((kind, path))
        with os.fdopen(fd, "w") as f:
            json.dump(data, f)
        return path

    def start(self):
        fd, self._params_file = tempfile.mkstemp(prefix="cloudgen-params-", suffix=".json")
        with os.fdopen(fd, "w") as f:
            json.dump(self.params, f)
        if self.sequence is not None:
            self._write_temp("sequence", self.sequence)
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
        progress = _PROGRESS.match(line)
        wrote = _WROTE.match(line)
        copied = _COPIED.match(line)
        kept = _KEPT.match(line)
        with self._lock:
            self.stdout_lines.append(line)
            if progress:
                self.progress = float(progress.group(1))
            if wrote:
                self.written.append(wrote.group(1))
            if copied:
                self.copied.append((copied.group(1), int(copied.group(2))))
            if kept:
                self.kept.append(kept.group(1))
        if progress and self.on_progress is not None:
            self.on_progress(self.progress)

    def _on_stderr(self, line):
        with self._lock:
            self.stderr_lines.append(line)

    @property
    def running(self) -> bool:
        return self._proc is not None and self._result is None and self._proc.poll() is None

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
        result = BakeResult(code, self._message(code), list(self.written), list(self.copied),
                            list(self.kept))
        if result.ok:
            result = self._verified(result)
        if result.ok:
            self.progress = 100.0
        self._result = result
        return result

    def _message(self, code):
        if code == OK:
            if self.copied or self.kept:
                return (f"{len(self.written)} baked, {len(self.copied)} copied, {len(self.kept)} kept"
                        f" ({len(self.written) + len(self.copied) + len(self.kept)} files)")
            return f"baked {len(self.written)} file(s): " + ", ".join(self.written)
        errors = [ln for ln in self.stderr_lines if ln.strip()]
        text = errors[-1] if errors else f"cloudgen bake exited with code {code}"
        text = re.sub(r"^cloudgen: (error: )?", "", text)
        if code == CANCELLED:
            return "bake cancelled; no partial file left" + (
                f" ({len(self.written)} finished frame(s) kept)" if self.written else "")
        return f"{_KIND.get(code, 'error')}: {text}"

    def _verified(self, result):
        expected = (sequence_paths(self.output, *self.frames) if self.frames is not None
                    else [self.output])
        missing = [p for p in expected if not os.path.isfile(p)]
        if missing:
            return BakeResult(IO_ERROR, f"I/O error: cloudgen reported success but {missing[0]} "
                                        "does not exist", list(result.paths), list(result.copied),
                              list(result.kept))
        if not self.verify:
            return result
        kept = {os.path.normpath(k) for k in result.kept}  # untouched: read back when written
        copies = {os.path.normpath(c): f for c, f in result.copied}
        for path in expected:
            if os.path.normpath(path) in kept:
                continue
            if os.path.normpath(path) in copies and self._same_size_as_source(path, copies):
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
                                            f"(disk full?): {why}; removed", [])
        return result

    def _same_size_as_source(self, path, copies):
        frame = copies[os.path.normpath(path)]
        source = sequence_paths(self.output, frame, frame)[0]
        try:
            return os.path.getsize(path) == os.path.getsize(source) > 0
        except OSError:
            return False

    def _cleanup(self):
        while self._temp_files:
            _, path = self._temp_files.pop()
            try:
                os.remove(path)
            except OSError:
                pass
        if self._params_file:
            try:
                os.remove(self._params_file)
            except OSError:
                pass
            self._params_file = None


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
