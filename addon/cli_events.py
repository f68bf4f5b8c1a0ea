"""The one reader of the cloudgen CLI's machine-readable output (`--json`,
docs/cli_protocol.md): one JSON object per line on stdout.

No bpy and no relative imports, so the add-on, bench/ and the tests all load
this same file:

    events = BakeEvents()
    for line in proc.stdout:
        events.feed(line)
    events.fraction, events.written, events.copied, events.kept, events.error

`cli_version(executable)` asks a CLI for its version and protocol once;
`check_protocol(...)` compares it with what this reader speaks.
"""
from __future__ import annotations

import json
import subprocess

PROTOCOL = 1  # the protocol this reader speaks (docs/cli_protocol.md)


class ProtocolError(RuntimeError):
    """The CLI printed something the protocol does not allow, or speaks another version."""


def parse(line: str):
    """The event of one stdout line (a dict with "event"), or None for an empty line.
    A line that is not a JSON object with an "event" is a ProtocolError."""
    text = line.strip()
    if not text:
        return None
    try:
        event = json.loads(text)
    except ValueError as exc:
        raise ProtocolError(f"not a JSON line: {text[:200]!r}") from exc
    if not isinstance(event, dict) or not isinstance(event.get("event"), str):
        raise ProtocolError(f"a JSON line without an \"event\": {text[:200]!r}")
    return event


class BakeEvents:
    """What a `cloudgen bake --json` run has said so far. Not thread-safe: feed from one thread."""

    def __init__(self):
        self.plan = None          # the plan event (its "files" name every output)
        self.camera = None        # the camera event, with --camera
        self.brick = None         # the brick event, with --brick
        self.fraction = 0.0       # 0..1 over the whole run
        self.written = []         # wrote events
        self.copied = []          # copied events
        self.kept = []            # kept events
        self.error = None         # the error event of a failed run
        self.unknown = []         # events this reader does not know (a newer CLI's additions)

    def feed(self, line: str):
        """Take one stdout line; returns its event (or None for an empty line)."""
        event = parse(line)
        if event is None:
            return None
        kind = event["event"]
        if kind == "plan":
            if event.get("protocol") != PROTOCOL:
                raise ProtocolError(f"the CLI speaks protocol {event.get('protocol')}, this reader {PROTOCOL}")
            self.plan = event
        elif kind == "camera":
            self.camera = event
        elif kind == "brick":
            self.brick = event
        elif kind == "progress":
            self.fraction = min(max(float(event["fraction"]), 0.0), 1.0)
        elif kind == "wrote":
            self.written.append(event)
        elif kind == "copied":
            self.copied.append(event)
        elif kind == "kept":
            self.kept.append(event)
        elif kind == "error":
            self.error = event
        elif kind != "frame":
            self.unknown.append(event)
        return event

    @property
    def files(self) -> list:
        """Every output the run names, in frame order (from the plan)."""
        return [f["path"] for f in (self.plan or {}).get("files", [])]

    def counts(self) -> str:
        """'3 baked, 2 copied, 0 kept'"""
        return f"{len(self.written)} baked, {len(self.copied)} copied, {len(self.kept)} kept"


def cli_version(executable) -> dict:
    """{"version": ..., "protocol": N} of a cloudgen executable; ProtocolError if it cannot say."""
    try:
        run = subprocess.run([str(executable), "--version", "--json"], stdin=subprocess.DEVNULL,
                             capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise ProtocolError(f"cannot run {executable} --version: {exc}") from exc
    try:
        info = json.loads(run.stdout)
    except ValueError:
        info = None
    if run.returncode != 0 or not isinstance(info, dict) or "protocol" not in info:
        raise ProtocolError(f"{executable} does not speak the JSON protocol (cloudgen --version --json "
                            f"printed {run.stdout.strip()[:120]!r}); use the cloudgen built with this release")
    return info


def check_protocol(info: dict, module_version: dict | None = None):
    """ProtocolError unless the CLI's protocol is ours and, given the module's
    version() dict, the CLI and the module are the same release."""
    if info.get("protocol") != PROTOCOL:
        raise ProtocolError(f"cloudgen {info.get('version')} speaks protocol {info.get('protocol')}, "
                            f"this reader {PROTOCOL}")
    if module_version is not None and module_version.get("version") != info.get("version"):
        raise ProtocolError(f"cloudgen {info.get('version')} and cloudgen_native {module_version.get('version')} "
                            "are different releases; install them together")
