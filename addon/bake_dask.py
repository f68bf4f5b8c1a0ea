"""Bake Frame Range on a Dask cluster: `<python> -m cloudgen_dask bake --scheduler ADDRESS
--sequence FILE --output OUT ... --json` (docs/distributed.md) in a subprocess,
with the BakeJob interface of bake_process (start, poll, wait, cancel, progress). No bpy.

The runner bakes each distinct field once on the cluster's workers (each runs the
cloudgen CLI at the same path, `--cloudgen`), copies the frames that repeat one, and
skips files that already hold their bake key. It runs with `--json` and speaks the
CLI's JSON-lines protocol on stdout (read with cli_events): `progress` events become
the job's progress, the `summary` event the result (`units`, `computed`, `skipped`,
`copied`), an `error` event the message. The files are the sequence's frames, named
as the CLI names them (frame_path). Cancel sends SIGINT (the runner cancels its
futures, keeps finished units and exits 130).
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import tempfile
import threading

try:
    from . import cli_events
    from .bake_process import BAD_ARGUMENT, CANCELLED, IO_ERROR, OK, BakeResult
except ImportError:
    import cli_events
    from bake_process import BAD_ARGUMENT, CANCELLED, IO_ERROR, OK, BakeResult


def command(python, scheduler, cli, sequence_file, output, resolution, extra):
    cmd = [python, "-m", "cloudgen_dask", "bake", "--scheduler", scheduler, "--json",
           "--cloudgen", cli, "--sequence", sequence_file, "--output", output]
    if resolution is not None:
        cmd += ["--resolution", str(int(resolution))]
    return cmd + list(extra)


class DaskBake:
    def __init__(self, python, scheduler, cli, sequence: dict, output, resolution, extra, files, frames,
                 on_progress=None):
        self.python, self.scheduler, self.cli = python, scheduler, cli
        self.sequence, self.output, self.resolution, self.extra = sequence, output, resolution, list(extra)
        self.files, self.frames = list(files), list(frames)
        self.on_progress = on_progress
        self.stderr_lines, self.stdout_lines = [], []
        self._fraction = 0.0
        self._proc = None
        self._seq_file = None
        self._threads = []
        self._result = None
        self._cancelled = False
        self._events = {}  # the runner's summary / error event

    @property
    def progress(self) -> float:
        return 100.0 * self._fraction

    def command(self):
        return command(self.python, self.scheduler, self.cli, self._seq_file or "SEQUENCE.json", self.output,
                       self.resolution, self.extra)

    def start(self):
        fd, self._seq_file = tempfile.mkstemp(prefix="cloudgen-sequence-", suffix=".json")
        with os.fdopen(fd, "w") as f:
            json.dump(self.sequence, f)
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        try:
            self._proc = subprocess.Popen(self.command(), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                          stderr=subprocess.PIPE, env=env)
        except OSError as exc:
            self._cleanup()
            self._result = BakeResult(BAD_ARGUMENT, f"cannot run the Dask runner {self.python}: {exc}")
            return self
        for stream, sink in ((self._proc.stdout, self.stdout_lines), (self._proc.stderr, self.stderr_lines)):
            t = threading.Thread(target=self._pump, args=(stream, sink), daemon=True)
            t.start()
            self._threads.append(t)
        return self

    def _pump(self, stream, sink):
        for raw in stream:
            line = raw.decode("utf-8", "replace").rstrip("\r\n")
            if not line.strip():
                continue
            sink.append(line)
            if sink is not self.stdout_lines:
                continue
            try:
                event = cli_events.parse(line)
            except cli_events.ProtocolError:
                continue  # not ours (a library printing on stdout): kept for the message only
            if event and event["event"] == "progress":
                self._fraction = min(max(float(event.get("fraction", 0.0)), 0.0), 1.0)
                if self.on_progress is not None:
                    self.on_progress(100.0 * self._fraction)
            elif event and event["event"] in ("summary", "error"):
                self._events[event["event"]] = event
        stream.close()

    def cancel(self):
        self._cancelled = True
        if self._proc is not None and self._proc.poll() is None:
            self._proc.send_signal(signal.SIGINT)

    def poll(self):
        if self._result is not None:
            return self._result
        if self._proc is None or self._proc.poll() is None:
            return None
        return self._finish()

    def wait(self, timeout=None):
        if self._result is None:
            self._proc.wait(timeout=timeout)
            self._finish()
        return self._result

    def _finish(self):
        for t in self._threads:
            t.join()
        self._cleanup()
        code = self._proc.returncode
        if code == 130 or (code < 0 and self._cancelled):
            self._result = BakeResult(CANCELLED, "bake cancelled; finished frames are kept on the cluster's storage")
            return self._result
        summary = self._events.get("summary")
        if code != OK or summary is None:
            error = self._events.get("error")
            if error is not None:
                text = str(error.get("message", ""))
            else:  # no event (the runner could not start): its last stderr line
                errors = [ln for ln in self.stderr_lines if "error" in ln] or self.stderr_lines or [f"exit code {code}"]
                text = re.sub(r"^cloudgen-dask: (error: )?", "", errors[-1])
            self._result = BakeResult(IO_ERROR if code != 2 else BAD_ARGUMENT, "Dask bake failed: " + text)
            return self._result
        missing = [f for f in self.files if not os.path.isfile(f)]
        if missing:
            self._result = BakeResult(IO_ERROR, f"the Dask runner reported success but {missing[0]} does not exist")
            return self._result
        result = BakeResult(OK, "", [], [], [], list(self.files), list(self.frames))
        result.counts_override = {"baked": int(summary.get("computed", 0)), "copied": int(summary.get("copied", 0)),
                                  "kept": int(summary.get("skipped", 0))}
        result.message = (f"on the Dask cluster {self.scheduler}: {summary.get('computed', 0)} baked, "
                          f"{summary.get('copied', 0)} copied, {summary.get('skipped', 0)} already done "
                          f"({len(self.files)} files)")
        self._fraction = 1.0
        self._result = result
        return result

    def _cleanup(self):
        if self._seq_file:
            try:
                os.remove(self._seq_file)
            except OSError:
                pass
            self._seq_file = None
