"""The external driver protocol of ``surfmap-rig --driver "CMD ARGS"`` in
Python, both ways (protocol 1; clients/rig/driver_protocol.h and the
README's "Connect your robot" are the reference).

- ``serve(measure)``: be a driver program. ``surfmap-rig --driver "python3
  my_driver.py"`` then leases, spools, submits and retries, and your program
  only measures: one command line in on stdin, one trace (or failure) line
  out on stdout. Log to stderr (or with ``log``): stdout carries the protocol.
- ``DriverProcess``: run a driver program and ask it for traces, e.g.
  ``surfmap-rig simulate-drag --sim plate`` (the simulated rig as a driver),
  which is how a driver skeleton sends its "hardware" to the simulator.

Messages are JSON objects, one per line::

    driver -> rig, first:  {"type":"ready","protocol":1,"driver":"UR5e + SensONE"}
    rig -> driver:         {"type":"command","protocol":1,"command_id":17,"job_id":3,"attempt":1,
                            "site":{"level":0,"vertex":12},"position_mm":[x,y,z],"normal":[x,y,z],
                            "drag_direction":[x,y,z],"segment_length_mm":20,"speed_mm_s":10,
                            "normal_force_n":5,"lease_deadline_unix_ms":1795000060000}
    driver -> rig:         {"type":"trace","command_id":17,"t":[..],"x":[..],"y":[..],"z":[..],
                            "fx":[..],"fy":[..],"fz":[..],"phase":["fwd",..,"pause",..,"rev",..]}
                       or  {"type":"failure","command_id":17,"kind":"transient"|"unreachable",
                            "reason":"...","stop":false}
    driver -> rig, any time: {"type":"log","message":"..."}
"""

from __future__ import annotations

import json
import subprocess
import sys
from datetime import datetime, timezone
from typing import IO, Callable, Optional, Sequence

import numpy as np

from . import probe
from . import records as r
from .errors import SurfmapError, invalid_argument
from .probe import FailureKind, ProbeCommand
from .rig import RigFailure

PROTOCOL_VERSION = 1


def ready_message(driver: str) -> dict:
    return {"type": "ready", "protocol": PROTOCOL_VERSION, "driver": driver}


def command_message(command: ProbeCommand) -> dict:
    """The command line's object for ``command``."""
    return {"type": "command", "protocol": PROTOCOL_VERSION, "command_id": command.command_id,
            "job_id": command.job_id, "attempt": command.attempt,
            "site": {"level": command.level, "vertex": command.vertex},
            "position_mm": [float(v) for v in command.position], "normal": [float(v) for v in command.normal],
            "drag_direction": [float(v) for v in command.drag_direction],
            "segment_length_mm": command.probe.segment_length_mm, "speed_mm_s": command.probe.speed_mm_s,
            "normal_force_n": command.probe.normal_force_n, "lease_deadline_unix_ms": command.lease_deadline_unix_ms}


def _field(message: dict, name: str, kind: type, what: str):
    value = message.get(name)
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        raise invalid_argument("driver", f"{what}: field '{name}' must be {kind.__name__}, got {value!r}")
    return value


def _vector(message: dict, name: str) -> np.ndarray:
    value = message.get(name)
    if not (isinstance(value, list) and len(value) == 3 and all(isinstance(v, (int, float)) for v in value)):
        raise invalid_argument("driver", f"command: field '{name}' must be an array of 3 numbers, got {value!r}")
    return np.array(value, dtype=float)


def command_from_message(message: dict) -> ProbeCommand:
    """A command line's object as a ProbeCommand (INVALID_ARGUMENT naming a bad field)."""
    if message.get("type") != "command":
        raise invalid_argument("driver", f"not a command message: {message!r:.80}")
    if message.get("protocol") != PROTOCOL_VERSION:
        raise invalid_argument("driver", f"command: protocol {message.get('protocol')!r} is not {PROTOCOL_VERSION}")
    site = message.get("site")
    if not isinstance(site, dict):
        raise invalid_argument("driver", "command: field 'site' must be an object {level, vertex}")
    deadline_ms = _field(message, "lease_deadline_unix_ms", int, "command")
    deadline = datetime.fromtimestamp(deadline_ms / 1000, tz=timezone.utc) if deadline_ms else None
    parameters = r.ProbeParameters(_field(message, "segment_length_mm", float, "command"),
                                   _field(message, "speed_mm_s", float, "command"),
                                   _field(message, "normal_force_n", float, "command"))
    return ProbeCommand(_field(message, "command_id", int, "command"), _field(message, "job_id", int, "command"),
                        _field(site, "level", int, "command: site"), _field(site, "vertex", int, "command: site"),
                        _vector(message, "position_mm"), _vector(message, "normal"), _vector(message, "drag_direction"),
                        parameters, _field(message, "attempt", int, "command"), deadline)


def trace_message(command_id: int, trace: r.Trace) -> dict:
    """The trace line's object (the trace must pass ``check_trace``: JSON has no NaN)."""
    xyz = np.asarray(trace.xyz, dtype=float)
    f = np.asarray(trace.f, dtype=float)
    names = {int(p): n for p, n in probe.PHASE_NAMES.items()}
    return {"type": "trace", "command_id": command_id, "t": np.asarray(trace.t, dtype=float).tolist(),
            "x": xyz[:, 0].tolist(), "y": xyz[:, 1].tolist(), "z": xyz[:, 2].tolist(),
            "fx": f[:, 0].tolist(), "fy": f[:, 1].tolist(), "fz": f[:, 2].tolist(),
            "phase": [names[int(p)] for p in trace.phase]}


def trace_from_message(message: dict, command: ProbeCommand) -> r.Trace:
    """A trace line's object as the client's Trace for ``command`` (checked)."""
    columns = []
    for name in ("t", "x", "y", "z", "fx", "fy", "fz"):
        column = message.get(name)
        if not isinstance(column, list):
            raise invalid_argument("driver", f"trace: field '{name}' must be an array of numbers")
        columns.append(column)
    phases = message.get("phase")
    if not isinstance(phases, list):
        raise invalid_argument("driver", "trace: field 'phase' must be an array of \"fwd\"/\"pause\"/\"rev\"")
    if len({len(c) for c in columns + [phases]}) != 1:
        raise invalid_argument("driver", f"trace: columns of different lengths {[len(c) for c in columns + [phases]]}")
    try:
        table = np.array(columns, dtype=float)
    except (TypeError, ValueError):
        raise invalid_argument("driver", "trace: a column holds something that is not a number") from None
    trace = probe.measured_trace(command, table[0], table[1:4].T, table[4:7].T, phases)
    probe.check_trace(trace, "driver")
    return trace


def failure_message(command_id: int, kind: FailureKind, reason: str, stop: bool = False) -> dict:
    return {"type": "failure", "command_id": command_id, "kind": FailureKind(kind).value, "reason": reason,
            "stop": stop}


def _write(stream: IO[str], message: dict) -> None:
    stream.write(json.dumps(message, allow_nan=False, separators=(",", ":")) + "\n")
    stream.flush()


def serve(measure: Callable[[ProbeCommand], r.Trace], name: str, stdin: Optional[IO[str]] = None,
          stdout: Optional[IO[str]] = None) -> int:
    """Be a driver program for ``surfmap-rig --driver``: says ready, then
    answers each command line with ``measure(command)``'s trace, or a failure
    when it raises ``RigFailure``. A trace ``check_trace`` refuses is answered
    as a transient failure naming the problem. Any other exception is
    answered as a transient failure with ``stop`` (the rig reports it and
    stops) and then propagates. Returns 0 at the end of stdin (the rig has no
    more commands: park the robot after this returns)."""
    stdin = stdin if stdin is not None else sys.stdin
    stdout = stdout if stdout is not None else sys.stdout
    _write(stdout, ready_message(name))
    for number, line in enumerate(stdin, start=1):
        if not line.strip():
            continue
        try:
            command = command_from_message(json.loads(line))
        except (ValueError, AttributeError) as error:
            raise SystemExit(f"driver: stdin line {number} is not a command: {error}") from None
        try:
            trace = measure(command)
            probe.check_trace(trace, "driver")
            reply = trace_message(command.command_id, trace)
        except RigFailure as failure:
            reply = failure_message(command.command_id, failure.kind, failure.reason, failure.stop)
        except SurfmapError as invalid:  # check_trace
            reply = failure_message(command.command_id, FailureKind.TRANSIENT, f"invalid trace: {invalid.message}")
        except Exception as bug:
            _write(stdout, failure_message(command.command_id, FailureKind.TRANSIENT,
                                           f"driver raised {type(bug).__name__}: {bug}", stop=True))
            raise
        _write(stdout, reply)
    return 0


def log(message: str, stdout: Optional[IO[str]] = None) -> None:
    """A log line for the rig to print (stdout carries the protocol: never print() there)."""
    _write(stdout if stdout is not None else sys.stdout, {"type": "log", "message": message})


class DriverProcess:
    """A driver program (argv, e.g. ``[surfmap_rig, "simulate-drag", "--sim",
    "plate"]``) as a child process, asked for one trace at a time. The
    constructor waits for its ready line; ``measure`` for its answer (no
    timeout: use it with programs you trust, such as the simulator). A context
    manager; ``close`` ends its stdin and waits for it."""

    def __init__(self, argv: Sequence[str], on_log: Optional[Callable[[str], None]] = None) -> None:
        self.argv = list(argv)
        self._on_log = on_log
        try:
            self._process = subprocess.Popen(self.argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                             bufsize=1)
        except OSError as error:
            raise invalid_argument("driver", f"cannot start {self.argv[0]}: {error}") from None
        while True:
            message = self._read()
            if message.get("type") == "log":
                self._log(message)
                continue
            if message.get("type") != "ready" or message.get("protocol") != PROTOCOL_VERSION:
                self.close()
                raise invalid_argument("driver", f"{self.argv[0]}: the first line must be a ready message of "
                                                 f"protocol {PROTOCOL_VERSION}, got {message!r:.120}")
            self.name = str(message.get("driver", ""))
            break

    def _log(self, message: dict) -> None:
        if self._on_log is not None:
            self._on_log(str(message.get("message", "")))

    def _read(self) -> dict:
        assert self._process.stdout is not None
        line = self._process.stdout.readline()
        if not line:
            code = self._process.wait()
            raise invalid_argument("driver", f"{' '.join(self.argv)} exited with code {code}")
        try:
            message = json.loads(line)
        except ValueError:
            raise invalid_argument("driver", f"{self.argv[0]} wrote a line that is not JSON: {line[:80]!r}") from None
        if not isinstance(message, dict):
            raise invalid_argument("driver", f"{self.argv[0]} wrote a line that is not a JSON object: {line[:80]!r}")
        return message

    def measure(self, command: ProbeCommand) -> r.Trace:
        """The program's trace for ``command``; its failure as ``RigFailure``."""
        assert self._process.stdin is not None
        _write(self._process.stdin, command_message(command))
        while True:
            message = self._read()
            kind = message.get("type")
            if kind == "log":
                self._log(message)
                continue
            if message.get("command_id") != command.command_id:
                raise invalid_argument("driver", f"answer for command {message.get('command_id')!r} while "
                                                 f"command {command.command_id} is being measured")
            if kind == "trace":
                return trace_from_message(message, command)
            if kind == "failure":
                raise RigFailure(str(message.get("reason", "")), message.get("kind", "transient"),
                                 bool(message.get("stop", False)))
            raise invalid_argument("driver", f"unknown message type {kind!r}")

    def close(self, timeout_s: float = 10.0) -> Optional[int]:
        """Closes its stdin and waits up to ``timeout_s`` (then kills it); returns its exit code."""
        if self._process.stdin is not None and not self._process.stdin.closed:
            self._process.stdin.close()
        try:
            return self._process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self._process.kill()
            return self._process.wait()

    def __enter__(self) -> "DriverProcess":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
