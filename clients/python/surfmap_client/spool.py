"""TraceSpool: where a rig keeps every measured trace until the server has
acknowledged it. The same directory layout, file format and lock as
``surfmap-rig`` (clients/rig/trace_spool.h, spool_file.h), so a C++ and
a Python rig with the same rig id find each other's traces::

    DIR/<measured_unix_ms>-command-<id>.trace.csv     waiting for an OK answer
    DIR/rejected/<same name>                          refused for good, with
    DIR/rejected/<same name>.reason                   the server's reason

A spool file is the drag-trace CSV (``surfmap fit`` reads it) under a fixed
header::

    # surfmap spooled trace v1
    # command_id: 17
    # job_id: 3
    # attempt: 1
    # rig_id: lab-arm-1
    # measured_unix_ms: 1795000000123
    # frame: rig_base                      only for a trace in a rig's frame
    # registration_id: 7                   (both, or neither)
    t,x,y,z,fx,fy,fz,phase
    0.0,9.9899,-5.0072,2.9973,-0.64094,-0.03418,6.09862,fwd

A file without ``frame`` (every file written before frames existed) holds a
trace in the object's frame. A spooled trace is resubmitted in the frame and
with the registration it was measured in, whatever the frame of the run that
resubmits it.
Numbers are written with ``repr`` (the shortest text that reads back to the
same double), so a resubmission is bit-identical to the first submission.
Files are written atomically (temp file, fsync, rename, fsync of the
directory). ``open`` takes an exclusive ``flock`` on DIR: one rig process per
spool.
"""

from __future__ import annotations

import fcntl
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import List, Optional, Union

import grpc
import numpy as np

from . import probe
from . import records as r
from .errors import SurfmapError, invalid_argument

VERSION_LINE = "# surfmap spooled trace v1"
HEADER_KEYS = ("command_id", "job_id", "attempt", "rig_id", "measured_unix_ms")
# The frames a spooled trace may be in (names as surfmap-rig's --frame).
SPOOL_FRAMES = ("object", "rig_base", "rig_base_sensor_forces")
CSV_HEADER = "t,x,y,z,fx,fy,fz,phase"
TRACE_SUFFIX = ".trace.csv"
REASON_SUFFIX = ".reason"
TEMP_PREFIX = ".tmp-"

PathLike = Union[str, os.PathLike]


@dataclass(frozen=True)
class SpoolHeader:
    """Who measured a spooled trace, for which command."""

    command_id: int
    job_id: int
    attempt: int
    rig_id: str
    measured_unix_ms: int
    frame: str = "object"         # the frame the trace's samples are in (SPOOL_FRAMES)
    registration_id: int = 0      # a rig frame's registration (0 = the latest)


@dataclass(frozen=True)
class SpooledTrace:
    header: SpoolHeader
    trace: r.Trace                # trace_id 0: not stored yet
    path: Path


def rig_id_path_component(rig_id: str) -> str:
    """The rig id as one path component, as surfmap-rig makes it: [A-Za-z0-9._-]
    kept, every other byte (UTF-8) as %XX; "." and ".." escaped too."""
    dots_only = rig_id.strip(".") == ""
    out = []
    for byte in rig_id.encode("utf-8"):
        c = chr(byte)
        if (c.isascii() and c.isalnum()) or c in "-_" or (c == "." and not dots_only):
            out.append(c)
        else:
            out.append(f"%{byte:02X}")
    return "".join(out)


def default_spool_dir(rig_id: str) -> Path:
    """``$XDG_STATE_HOME/surfmap/spool/<rig id>``, else ``~/.local/state/surfmap/spool/<rig id>``
    (the same directory surfmap-rig uses for this rig id)."""
    tail = Path("surfmap") / "spool" / rig_id_path_component(rig_id)
    xdg = os.environ.get("XDG_STATE_HOME", "")
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / tail
    home = os.environ.get("HOME", "")
    if home and os.path.isabs(home):
        return Path(home) / ".local" / "state" / tail
    raise SurfmapError(grpc.StatusCode.FAILED_PRECONDITION,
                       "no spool directory: neither XDG_STATE_HOME nor HOME is an absolute path; pass spool_dir",
                       "spool")


def check_header(header: SpoolHeader, method: str = "spool") -> None:
    """INVALID_ARGUMENT naming the field, as surfmap-rig checks it."""
    if header.command_id <= 0:
        raise invalid_argument(method, f"command_id {header.command_id} is not a command id (> 0)")
    if header.job_id <= 0:
        raise invalid_argument(method, f"job_id {header.job_id} is not a job id (> 0)")
    if header.attempt < 0:
        raise invalid_argument(method, f"attempt {header.attempt} is < 0")
    if not 1 <= len(header.rig_id.encode("utf-8")) <= 100:
        raise invalid_argument(method, f"rig_id must have 1..100 characters, has {len(header.rig_id)}")
    if any(ord(c) < 0x20 or ord(c) == 0x7F for c in header.rig_id):
        raise invalid_argument(method, "rig_id must not contain control characters (newline, tab, ...)")
    if header.frame not in SPOOL_FRAMES:
        raise invalid_argument(method, f"unknown trace frame \"{header.frame}\"; expected object, rig_base or "
                                       "rig_base_sensor_forces")
    if header.registration_id < 0:
        raise invalid_argument(method, f"registration_id {header.registration_id} is < 0")
    if header.frame == "object" and header.registration_id != 0:
        raise invalid_argument(method, f"registration_id {header.registration_id} with the object's frame "
                                       "(a registration is for a rig frame)")


def format_spool_file(header: SpoolHeader, trace: r.Trace) -> str:
    """The file's text (header checked, trace not)."""
    check_header(header)
    lines = [VERSION_LINE, f"# command_id: {header.command_id}", f"# job_id: {header.job_id}",
             f"# attempt: {header.attempt}", f"# rig_id: {header.rig_id}",
             f"# measured_unix_ms: {header.measured_unix_ms}"]
    # Object-frame files stay as before frames existed (older rigs read them).
    if header.frame != "object":
        lines += [f"# frame: {header.frame}", f"# registration_id: {header.registration_id}"]
    lines.append(CSV_HEADER)
    xyz = np.asarray(trace.xyz, dtype=float)
    f = np.asarray(trace.f, dtype=float)
    names = {int(p): n for p, n in probe.PHASE_NAMES.items()}
    for i, t in enumerate(np.asarray(trace.t, dtype=float).tolist()):
        values = (t, *xyz[i].tolist(), *f[i].tolist())
        lines.append(",".join(repr(v) for v in values) + "," + names.get(int(trace.phase[i]), "unspecified"))
    return "\n".join(lines) + "\n"


def parse_spool_file(text: str, source: str) -> tuple[SpoolHeader, r.Trace]:
    """Parses a spool file (C++ or Python written). INVALID_ARGUMENT
    "<source>:<line>: <problem>" for anything that is not exactly the format,
    and for a trace ``check_trace`` refuses."""
    def error(line: int, problem: str) -> SurfmapError:
        return invalid_argument("spool", f"{source}:{line}: {problem}")

    lines = text.split("\n")
    if lines[0].rstrip("\r") != VERSION_LINE:
        raise error(1, f"not a spool file: the first line must be '{VERSION_LINE}'")
    numbers: dict[str, int] = {}
    rig_id = ""
    for k, key in enumerate(HEADER_KEYS):
        number = k + 2
        if number > len(lines):
            raise error(number, f"missing header key '{key}'")
        line = lines[number - 1].rstrip("\r")
        prefix = f"# {key}: "
        if not line.startswith(prefix):
            raise error(number, f"expected '{prefix}<value>', found '{line[:60]}'")
        value = line[len(prefix):]
        if key == "rig_id":
            rig_id = value
            continue
        try:
            numbers[key] = int(value)
        except ValueError:
            raise error(number, f"{key} '{value}' is not an integer") from None
    # The optional frame keys: both or neither.
    frame, registration_id = "object", 0
    first = len(HEADER_KEYS) + 2
    if first <= len(lines) and lines[first - 1].startswith("# frame: "):
        frame = lines[first - 1].rstrip("\r")[len("# frame: "):]
        if frame not in SPOOL_FRAMES:
            raise error(first, f"frame: unknown trace frame \"{frame}\"; expected object, rig_base or "
                               "rig_base_sensor_forces")
        line = lines[first].rstrip("\r") if first < len(lines) else ""
        prefix = "# registration_id: "
        if not line.startswith(prefix):
            raise error(first + 1, f"expected '{prefix}<value>' after the frame, found '{line[:60]}'")
        try:
            registration_id = int(line[len(prefix):])
        except ValueError:
            raise error(first + 1, f"registration_id '{line[len(prefix):]}' is not an integer") from None
        first += 2
    header = SpoolHeader(numbers["command_id"], numbers["job_id"], numbers["attempt"], rig_id,
                         numbers["measured_unix_ms"], frame, registration_id)
    try:
        check_header(header)
    except SurfmapError as bad:
        raise error(2, f"header: {bad.message}") from None
    while first <= len(lines) and (not lines[first - 1].strip() or lines[first - 1].lstrip().startswith("#")):
        first += 1
    if first > len(lines) or lines[first - 1].strip().replace(" ", "") != CSV_HEADER:
        raise error(first, f"expected the CSV header '{CSV_HEADER}'")
    rows = []
    for number in range(first + 1, len(lines) + 1):
        line = lines[number - 1].strip()
        if not line or line.startswith("#"):
            continue
        fields = [x.strip() for x in line.split(",")]
        if len(fields) != 8:
            raise error(number, f"expected 8 fields, found {len(fields)}")
        try:
            values = [float(x) for x in fields[:7]]
        except ValueError:
            raise error(number, f"a value of '{line[:60]}' is not a number") from None
        if fields[7] not in probe.PHASE_FROM_NAME:
            raise error(number, f"unknown phase '{fields[7]}'")
        rows.append((*values, int(probe.PHASE_FROM_NAME[fields[7]])))
    if not rows:
        raise error(len(lines), "no samples")
    table = np.array([row[:7] for row in rows], dtype=float)
    trace = r.Trace(trace_id=0, command_id=header.command_id, job_id=header.job_id, t=table[:, 0].copy(),
                    xyz=table[:, 1:4].copy(), f=table[:, 4:7].copy(),
                    phase=np.array([row[7] for row in rows], dtype=np.int8))
    try:
        probe.check_trace(trace, "spool")
    except SurfmapError as bad:
        raise error(first, bad.message) from None
    return header, trace


def _write_atomically(target: Path, text: str) -> None:
    temp = target.parent / f"{TEMP_PREFIX}{target.name}.{os.getpid()}"
    try:
        with open(temp, "w", encoding="utf-8", newline="\n") as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        os.rename(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    _sync_directory(target.parent)


def _sync_directory(directory: Path) -> None:
    fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class TraceSpool:
    """A locked spool directory (see the module's docstring). A context manager."""

    def __init__(self, directory: Path, lock_fd: int) -> None:
        self.directory = directory
        self._lock_fd: Optional[int] = lock_fd

    @classmethod
    def open(cls, directory: PathLike) -> "TraceSpool":
        """Creates DIR and DIR/rejected, locks DIR, deletes temp files left by
        an interrupted write. FAILED_PRECONDITION when another process holds
        the spool; PERMISSION_DENIED naming the path when it cannot be created."""
        path = Path(os.path.abspath(os.fspath(directory)))
        try:
            (path / "rejected").mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
        except OSError as error:
            raise SurfmapError(grpc.StatusCode.PERMISSION_DENIED,
                               f"cannot create spool directory {path}: {error.strerror}", "spool") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise SurfmapError(grpc.StatusCode.FAILED_PRECONDITION,
                               f"spool {path} is in use by another rig process (each rig needs its own spool: "
                               "a different rig id or spool_dir)", "spool") from None
        for d in (path, path / "rejected"):
            for entry in d.iterdir():
                if entry.name.startswith(TEMP_PREFIX):
                    entry.unlink(missing_ok=True)
        return cls(path, fd)

    @property
    def rejected_dir(self) -> Path:
        return self.directory / "rejected"

    def close(self) -> None:
        """Releases the lock."""
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def __enter__(self) -> "TraceSpool":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def add(self, header: SpoolHeader, trace: r.Trace) -> Path:
        """Spools a measured trace; returns its file. INVALID_ARGUMENT for a
        trace ``check_trace`` refuses (keep it with ``reject_invalid``)."""
        probe.check_trace(trace, "spool")
        text = format_spool_file(header, trace)
        name = f"{header.measured_unix_ms:013d}-command-{header.command_id}"
        path = self.directory / f"{name}{TRACE_SUFFIX}"
        n = 2
        while path.exists() or (self.rejected_dir / path.name).exists():
            path = self.directory / f"{name}-{n}{TRACE_SUFFIX}"
            n += 1
        _write_atomically(path, text)
        return path

    def pending(self) -> List[Path]:
        """The traces waiting, oldest first."""
        return sorted(p for p in self.directory.iterdir()
                      if p.name.endswith(TRACE_SUFFIX) and not p.name.startswith(TEMP_PREFIX) and p.is_file())

    def read(self, path: Path) -> SpooledTrace:
        """A spooled file (parse errors as parse_spool_file's)."""
        header, trace = parse_spool_file(Path(path).read_text(encoding="utf-8"), str(path))
        return SpooledTrace(header, trace, Path(path))

    def remove(self, path: Path) -> None:
        """After an OK answer. Not made durable (no directory fsync): a file a
        crash brings back is resubmitted and answered already_accepted."""
        self._check_in_spool(path)
        Path(path).unlink()

    def reject(self, path: Path, reason: str) -> Path:
        """Moves a spooled file to rejected/, writing the reason beside it first; returns the new path."""
        self._check_in_spool(path)
        target = self.rejected_dir / Path(path).name
        _write_atomically(Path(str(target) + REASON_SUFFIX),
                          f"{reason}\nrejected_unix_ms: {int(time.time() * 1000)}\n")
        os.rename(path, target)
        _sync_directory(self.rejected_dir)
        _sync_directory(self.directory)
        return target

    def reject_invalid(self, header: SpoolHeader, trace: r.Trace, problem: str) -> Optional[Path]:
        """Keeps a trace that cannot be submitted in rejected/ with the problem
        (when it has a trace's shape: otherwise there is nothing to write)."""
        if not _has_trace_shape(trace):
            return None
        name = f"{header.measured_unix_ms:013d}-command-{header.command_id}{TRACE_SUFFIX}"
        target = self.rejected_dir / name
        _write_atomically(target, format_spool_file(header, trace))
        _write_atomically(Path(str(target) + REASON_SUFFIX), f"not submitted: the trace is invalid: {problem}\n")
        return target

    def remove_directories_if_empty(self) -> None:
        """At exit: removes rejected/ and DIR when both are empty."""
        for d in (self.rejected_dir, self.directory):
            try:
                d.rmdir()
            except OSError:
                pass

    def _check_in_spool(self, path: Path) -> None:
        if Path(path).parent != self.directory:
            raise invalid_argument("spool", f"{path} is not a file of the spool {self.directory}")


def _has_trace_shape(trace: r.Trace) -> bool:
    try:
        n = np.asarray(trace.t).shape[0]
        return (np.asarray(trace.t).ndim == 1 and np.asarray(trace.xyz).shape == (n, 3)
                and np.asarray(trace.f).shape == (n, 3) and np.asarray(trace.phase).shape == (n,))
    except (IndexError, TypeError, ValueError):
        return False
