"""A rig in Python: lease probe commands, measure them with your own code,
submit the traces, report what could not be measured.

    import surfmap_client as sc

    def measure(command: sc.ProbeCommand) -> sc.Trace:
        ...   # drive the robot; raise sc.RigFailure("why", kind="unreachable") when it cannot
        return sc.measured_trace(command, t, xyz, f, phase)

    with sc.connect("lab-server:50051") as client:
        summary = sc.run_rig(client, measure, rig_id="arm-1", job_id=3)
        print(summary.format("arm-1"))

The same rules as ``surfmap-rig`` (clients/rig/README.md):

- Every measured trace is written to the rig's spool (``spool.py``) BEFORE it
  is submitted and deleted only after an OK answer (fresh or
  ``already_accepted``); ``run`` resubmits what a crashed run left first.
- UNAVAILABLE and DEADLINE_EXCEEDED (server down, restarting, busy) are
  retried with capped exponential backoff for ``retry_for_s`` per call, and
  each wait is announced ("server unavailable, retrying for 4 min 50 s (...)").
  When the time runs out the trace stays in the spool (``TracePending``).
- A definitive refusal (ALREADY_EXISTS: another rig measured the command;
  FAILED_PRECONDITION: the lease was lost or the job ended; NOT_FOUND;
  INVALID_ARGUMENT / RESOURCE_EXHAUSTED: the server cannot use the trace)
  moves the file to ``<spool>/rejected/`` with a ``.reason`` file beside it
  (``TraceRejected``): never silently dropped.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, List, Optional, Union

import grpc

from . import probe
from . import records as r
from ._stubs import pb, pb_grpc
from .client import SurfmapClient
from .errors import SurfmapError, error_from_rpc, invalid_argument
from .probe import FailureKind, Lease, ProbeCommand, SubmitResult
from .spool import SpoolHeader, TraceSpool, default_spool_dir

DEFAULT_RETRY_FOR_S = 300.0
RETRYABLE = (grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.DEADLINE_EXCEEDED)
# Refusals that resubmitting cannot change.
DEFINITIVE = (grpc.StatusCode.ALREADY_EXISTS, grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.NOT_FOUND,
              grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.RESOURCE_EXHAUSTED)
# Of those, the ones where the site should be measured again.
UNUSABLE = (grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.RESOURCE_EXHAUSTED)

_log = logging.getLogger("surfmap_client.rig")

Measure = Callable[[ProbeCommand], r.Trace]


# The frames a trace may be sent in (SubmitTraceRequest.frame).
TRACE_FRAMES = {"object": pb.TRACE_FRAME_OBJECT, "rig_base": pb.TRACE_FRAME_RIG_BASE,
                "rig_base_sensor_forces": pb.TRACE_FRAME_RIG_BASE_SENSOR_FORCES}


class RigFailure(Exception):
    """Raised by a ``measure`` function when it could not measure the command.

    ``kind``: "transient" (try again later: force limit tripped, lost contact;
    the site is re-queued up to the job's max_retries) or "unreachable" (this
    rig can never reach the site: outside its workspace; the site is given up).
    ``stop``: the rig loop stops after reporting (an emergency stop, an
    operator's abort).
    """

    def __init__(self, reason: str, kind: Union[FailureKind, str] = FailureKind.TRANSIENT, stop: bool = False) -> None:
        super().__init__(reason)
        self.reason = reason
        self.kind = probe.failure_kind(kind, "RigFailure")
        self.stop = stop


class TraceRejected(SurfmapError):
    """The server refused a trace for good; it is kept at ``path`` (under
    ``<spool>/rejected/``) with the reason in ``path + '.reason'``."""

    def __init__(self, cause: SurfmapError, path: Optional[Path]) -> None:
        kept = f"; trace kept in {path}" if path is not None else ""
        super().__init__(cause.code, cause.message + kept, cause.method)
        self.reason = cause.message
        self.path = path


class TracePending(SurfmapError):
    """A trace could not be delivered (retries ran out, or an error such as
    UNAUTHENTICATED); it stays in the spool at ``path`` and is resubmitted by
    ``resubmit_spool`` / the next ``run``."""

    def __init__(self, cause: SurfmapError, path: Path) -> None:
        super().__init__(cause.code, f"{cause.message}; the trace stays in {path} and is resubmitted by the next run",
                         cause.method)
        self.path = path


@dataclass
class RigSummary:
    """What a ``run`` did (the counters of surfmap-rig's summary line)."""

    accepted: int = 0            # this run's traces the server accepted (incl. already_accepted)
    already_accepted: int = 0
    resubmitted: int = 0         # traces an earlier run had spooled, accepted now
    rejected: int = 0            # traces moved to <spool>/rejected/
    failures: int = 0            # commands reported as failed
    abandoned: int = 0           # commands whose lease was lost, answered by another rig, or whose job ended
    retries: int = 0             # calls repeated after UNAVAILABLE / DEADLINE_EXCEEDED
    spooled_left: int = 0        # traces still in the spool at the end
    elapsed_s: float = 0.0
    job_finished: bool = False
    stopped: bool = False        # ended by the stop event
    reached_max_commands: bool = False
    error: Optional[SurfmapError] = None   # what ended the run early (None otherwise)
    events: List[str] = field(default_factory=list)  # every event line, in order

    @property
    def executed(self) -> int:
        return self.accepted + self.failures + self.abandoned

    def format(self, rig_id: str) -> str:
        """One line, as surfmap-rig prints it."""
        def plural(n: int, one: str, many: str) -> str:
            return f"{n} {one if n == 1 else many}"
        rate = self.accepted / self.elapsed_s if self.elapsed_s > 0 else 0.0
        line = (f"{rig_id}: {plural(self.accepted, 'command', 'commands')} done, "
                f"{plural(self.failures, 'failure', 'failures')}, {self.abandoned} abandoned, "
                f"{plural(self.retries, 'retry', 'retries')} in {self.elapsed_s:.1f} s ({rate:.2f} traces/s)")
        if self.resubmitted:
            line += f"; {plural(self.resubmitted, 'spooled trace', 'spooled traces')} resubmitted"
        if self.rejected:
            line += f"; {plural(self.rejected, 'trace', 'traces')} rejected"
        if self.spooled_left:
            line += f"; {plural(self.spooled_left, 'trace', 'traces')} left in the spool"
        for flag, text in ((self.job_finished, "job finished"), (self.reached_max_commands, "max_commands reached"),
                           (self.stopped, "stopped"), (self.error is not None, "ended by an error")):
            if flag:
                line += f"; {text}"
        return line

    def raise_for_error(self) -> "RigSummary":
        """Raises ``error`` when the run ended by one; returns self otherwise."""
        if self.error is not None:
            raise self.error
        return self


def format_wait_duration(seconds: float) -> str:
    """"4 min 50 s", "50 s", "1.5 s", "2 h 5 min" (as surfmap-rig says it)."""
    if not seconds > 0:
        return "0 s"
    if seconds < 10:
        return f"{seconds:.1f} s"
    whole = int(math.floor(seconds + 0.5))
    if whole < 60:
        return f"{whole} s"
    if whole < 3600:
        return f"{whole // 60} min" if whole % 60 == 0 else f"{whole // 60} min {whole % 60} s"
    minutes = (whole % 3600) // 60
    return f"{whole // 3600} h" if minutes == 0 else f"{whole // 3600} h {minutes} min"


def format_retry_notice(error: SurfmapError, remaining_s: float) -> str:
    """"server unavailable, retrying for 4 min 50 s (SubmitTrace: UNAVAILABLE: ...)"."""
    what = "server not answering" if error.code == grpc.StatusCode.DEADLINE_EXCEEDED else "server unavailable"
    return (f"{what}, retrying for {format_wait_duration(remaining_s)} "
            f"({error.method}: {error.code.name}: {error.message})")


class Rig:
    """One rig (``rig_id``) of a surfmapd: lease, submit, report, run.

    ``spool_dir``: where measured traces wait for their acknowledgement
    (default ``default_spool_dir(rig_id)``, the one surfmap-rig uses for the
    same id; locked while the Rig is open). ``retry_for_s``: how long each
    call is retried while the server is unavailable. ``on_event``: receives
    each event line (retries, refusals, failures); default: the
    ``surfmap_client.rig`` logger. ``sleep`` and ``clock`` are for tests.
    Not thread-safe: one Rig measures one command at a time. A context
    manager; ``close`` releases the spool.
    """

    def __init__(self, client: SurfmapClient, rig_id: str, spool_dir: Optional[Union[str, Path]] = None,
                 retry_for_s: float = DEFAULT_RETRY_FOR_S, *, initial_backoff_s: float = 0.2,
                 max_backoff_s: float = 5.0, max_retry_after_s: float = 10.0,
                 on_event: Optional[Callable[[str], None]] = None,
                 sleep: Callable[[float], None] = time.sleep, clock: Callable[[], float] = time.monotonic,
                 frame: str = "object") -> None:
        if not isinstance(rig_id, str) or not 1 <= len(rig_id) <= 100:
            raise invalid_argument("Rig", f"rig_id must have 1..100 characters, got {rig_id!r}")
        if any(ord(c) < 0x20 or ord(c) == 0x7F for c in rig_id):
            raise invalid_argument("Rig", "rig_id must not contain control characters (newline, tab, ...)")
        if retry_for_s is None or not math.isfinite(retry_for_s) or retry_for_s < 0:
            raise invalid_argument("Rig", f"retry_for_s must be >= 0, got {retry_for_s!r}")
        probe.finite_positive(initial_backoff_s, "initial_backoff_s", "Rig")
        if probe.finite_positive(max_backoff_s, "max_backoff_s", "Rig") < initial_backoff_s:
            raise invalid_argument("Rig", "max_backoff_s must be >= initial_backoff_s")
        probe.finite_positive(max_retry_after_s, "max_retry_after_s", "Rig")
        if frame not in TRACE_FRAMES:
            raise invalid_argument("Rig", f"frame must be one of {', '.join(TRACE_FRAMES)}, got {frame!r}")
        self.frame = frame
        self.client = client
        self.rig_id = rig_id
        self.retry_for_s = float(retry_for_s)
        self.initial_backoff_s = initial_backoff_s
        self.max_backoff_s = max_backoff_s
        self.max_retry_after_s = max_retry_after_s
        self._on_event = on_event
        self._sleep = sleep
        self._clock = clock
        self.spool = TraceSpool.open(spool_dir if spool_dir is not None else default_spool_dir(rig_id))
        self._channel = client.new_channel()
        self._stub = pb_grpc.ProbeServiceStub(self._channel)
        self._reconnect = False
        self._summary = RigSummary()  # the counters of the current run (or of direct calls)

    # ------------------------------------------------------------ plumbing

    def close(self) -> None:
        """Releases the spool (removing its directories when empty) and the channel."""
        self.spool.remove_directories_if_empty()
        self.spool.close()
        if self._channel is not getattr(self.client, "_channel", None):
            self._channel.close()

    def __enter__(self) -> "Rig":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _event(self, line: str) -> None:
        self._summary.events.append(line)
        if self._on_event is not None:
            self._on_event(line)
        else:
            _log.warning("%s", line)

    def _call_once(self, method: str, request):
        if self._reconnect:
            # A fresh connection: the old channel may sit in TRANSIENT_FAILURE
            # for seconds after the server is back.
            old = self._channel
            self._channel = self.client.new_channel()
            self._stub = pb_grpc.ProbeServiceStub(self._channel)
            if old is not getattr(self.client, "_channel", None) and old is not self._channel:
                old.close()
            self._reconnect = False
        rpc = getattr(self._stub, method)
        try:
            return rpc(request, timeout=self.client.timeout, metadata=self.client.metadata)
        except grpc.RpcError as rpc_error:
            error = error_from_rpc(rpc_error, method)
            if error.code == grpc.StatusCode.UNAVAILABLE:
                self._reconnect = True
            raise error from None

    def _wait(self, seconds: float, stop: Optional[threading.Event]) -> None:
        """Sleeps, waking at once when ``stop`` is set."""
        if stop is not None:
            stop.wait(seconds)
        else:
            self._sleep(seconds)

    def _call(self, method: str, request, stop: Optional[threading.Event] = None):
        """Calls until OK, a non-retryable error, ``retry_for_s`` after the
        first failure, or (for LeaseCommand) ``stop``. Raises the last error."""
        backoff = self.initial_backoff_s
        first_failure: Optional[float] = None
        while True:
            try:
                return self._call_once(method, request)
            except SurfmapError as error:
                if error.code not in RETRYABLE:
                    raise
                now = self._clock()
                first_failure = now if first_failure is None else first_failure
                left = self.retry_for_s - (now - first_failure)
                if left <= 0:
                    self._event(f"{self.rig_id}: {method}: {error.code.name}: {error.message}; gave up after "
                                f"retrying for {format_wait_duration(self.retry_for_s)}")
                    raise
                wait = min(backoff, left)
                self._summary.retries += 1
                self._event(f"{self.rig_id}: {format_retry_notice(error, left)}")
                self._wait(wait, stop if method == "LeaseCommand" else None)
                if stop is not None and stop.is_set() and method == "LeaseCommand":
                    raise
                backoff = min(backoff * 2.0, self.max_backoff_s)

    # ------------------------------------------------------------ the API

    def lease(self, job_id: int = 0, stop: Optional[threading.Event] = None) -> Lease:
        """Leases a command of ``job_id`` (0 = any running job) for this rig."""
        request = pb.LeaseCommandRequest(rig_id=self.rig_id, job_id=job_id)
        return probe.lease(self._call("LeaseCommand", request, stop))

    def submit(self, command: ProbeCommand, trace: r.Trace, lease_next: bool = False) -> SubmitResult:
        """Spools ``trace`` (measured for ``command`` by this rig), submits it
        and deletes the spooled copy on an OK answer.

        Raises ``TraceRejected`` for a definitive refusal (the trace is kept
        in ``<spool>/rejected/`` with the reason; also for a trace
        ``check_trace`` refuses, which is never sent) and ``TracePending`` when
        it could not be delivered (it stays in the spool). ``lease_next``:
        also lease this rig's next command of the job in the same write
        (``result.next``).
        """
        # The frame and registration go with the trace: a later run resubmits it
        # in them, whatever its own frame.
        registration_id = 0
        if self.frame != "object" and command.rig_frame is not None:
            registration_id = command.rig_frame.registration_id
        header = SpoolHeader(command.command_id, command.job_id, command.attempt, self.rig_id,
                             int(time.time() * 1000), self.frame, registration_id)
        try:
            path = self.spool.add(header, trace)
        except SurfmapError as invalid:
            kept = self.spool.reject_invalid(header, trace, invalid.message)
            self._summary.rejected += 1 if kept is not None else 0
            raise TraceRejected(SurfmapError(invalid.code, f"invalid trace: {invalid.message}", "SubmitTrace"),
                                kept) from None
        return self._deliver(path, header, trace, lease_next)

    def report_failure(self, command: Union[ProbeCommand, int], reason: str,
                       kind: Union[FailureKind, str] = FailureKind.TRANSIENT) -> bool:
        """Tells the server this rig could not measure ``command``; returns
        whether the site will be tried again. ``kind``: "transient" (re-queued
        up to the job's max_retries) or "unreachable" (given up at once).
        ``reason`` (1..1000 characters) is shown to operators."""
        failure = probe.failure_kind(kind)
        if not isinstance(reason, str) or not reason.strip():
            raise invalid_argument("ReportFailure", "reason must say what went wrong (1..1000 characters)")
        command_id = command.command_id if isinstance(command, ProbeCommand) else int(command)
        request = pb.ReportFailureRequest(command_id=command_id, rig_id=self.rig_id, reason=reason[:1000],
                                          kind=probe.FAILURE_KIND_TO_PROTO[failure])
        return self._call("ReportFailure", request).will_retry

    def resubmit_spool(self) -> RigSummary:
        """Delivers every trace left in the spool (oldest first, ``lease_next``
        off). Accepted ones count as ``resubmitted``; refused ones go to
        rejected/ (a trace the server cannot use is also reported as a
        transient failure so its site is measured again). Stops at the first
        trace that cannot be delivered (``error`` set, the trace kept)."""
        self._summary = RigSummary()
        self._resubmit_spool()
        self._summary.spooled_left = len(self.spool.pending())
        return self._summary

    def run(self, measure: Measure, job_id: int = 0, max_commands: int = 0,
            stop: Optional[threading.Event] = None,
            on_progress: Optional[Callable[[r.JobProgress], None]] = None) -> RigSummary:
        """The rig loop: resubmit the spool, then lease -> ``measure(command)``
        -> submit until the job finishes, ``max_commands`` commands are done
        (0 = no limit), ``stop`` is set, or something fails for good
        (``summary.error``; ``summary.raise_for_error()`` raises it).

        ``measure`` returns the ``Trace`` (``measured_trace``) or raises
        ``RigFailure`` (reported with its kind; ``stop=True`` also ends the
        run). Any other exception from ``measure`` is reported as a transient
        failure and then propagates (a bug in the driver must not go on
        driving a robot). ``on_progress`` gets the job's progress after each
        accepted trace.
        """
        if max_commands < 0:
            raise invalid_argument("run", f"max_commands must be >= 0, got {max_commands}")
        self._summary = summary = RigSummary()
        start = self._clock()
        try:
            if self._resubmit_spool():
                next_lease: Optional[Lease] = None
                while True:
                    if stop is not None and stop.is_set():
                        summary.stopped = True
                        break
                    if max_commands and summary.executed >= max_commands:
                        summary.reached_max_commands = True
                        break
                    if next_lease is None:
                        try:
                            next_lease = self.lease(job_id, stop)
                        except SurfmapError as error:
                            if stop is not None and stop.is_set():
                                continue
                            summary.error = error
                            break
                    current, next_lease = next_lease, None
                    if current.job_finished:
                        summary.job_finished = True
                        break
                    if current.command is None:
                        self._wait(min(current.retry_after_s or 1.0, self.max_retry_after_s), stop)
                        continue
                    outcome = self._run_command(measure, current.command, stop, max_commands, on_progress)
                    if outcome is False:
                        break
                    next_lease = outcome if isinstance(outcome, Lease) else None
        finally:
            summary.spooled_left = len(self.spool.pending())
            summary.elapsed_s = self._clock() - start
        return summary

    # ------------------------------------------------------------ internals

    def _where(self, command: ProbeCommand) -> str:
        return f"command {command.command_id} (L{command.level} v{command.vertex})"

    def _report(self, command_id: int, where: str, reason: str, kind: FailureKind, count: bool = True) -> bool:
        """ReportFailure inside the loop: False when the loop must end (summary.error set)."""
        try:
            will_retry = self.report_failure(command_id, reason, kind)
        except SurfmapError as error:
            if error.code in (grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.NOT_FOUND):
                self._summary.abandoned += 1 if count else 0
                self._event(f"{self.rig_id}: ReportFailure: {error.code.name}: {error.message}")
                return True
            self._summary.error = error
            return False
        self._summary.failures += 1 if count else 0
        self._event(f"{self.rig_id}: {where} failed ({kind.value}{', will be retried' if will_retry else ''}): "
                    f"{reason}")
        return True

    def _deliver(self, path: Path, header: SpoolHeader, trace: r.Trace, lease_next: bool) -> SubmitResult:
        request = pb.SubmitTraceRequest(command_id=header.command_id, rig_id=header.rig_id,
                                        samples=probe.trace_samples(trace), lease_next=lease_next,
                                        frame=TRACE_FRAMES[header.frame],
                                        registration_id=header.registration_id)
        try:
            result = probe.submit_result(self._call("SubmitTrace", request))
        except SurfmapError as error:
            if error.code in DEFINITIVE:
                kept = self.spool.reject(path, f"SubmitTrace: {error.code.name}: {error.message}")
                self._summary.rejected += 1
                self._event(f"{self.rig_id}: SubmitTrace: {error.code.name}: {error.message}; trace kept in {kept}")
                raise TraceRejected(error, kept) from None
            self._event(f"{self.rig_id}: the trace for command {header.command_id} stays in {path}: it is "
                        "resubmitted when the rig starts again")
            raise TracePending(error, path) from None
        try:
            self.spool.remove(path)
        except OSError as error:  # harmless: resubmitting it later is answered already_accepted
            self._event(f"{self.rig_id}: accepted, but the spooled copy stays: {error}")
        if result.already_accepted:
            self._summary.already_accepted += 1
        return result

    def _resubmit_spool(self) -> bool:
        """False when the run must end (summary.error set)."""
        files = self.spool.pending()
        if files:
            self._event(f"{self.rig_id}: resubmitting {len(files)} spooled "
                        f"trace{'' if len(files) == 1 else 's'} from {self.spool.directory}")
        for path in files:
            try:
                spooled = self.spool.read(path)
            except FileNotFoundError:
                continue
            except SurfmapError as unreadable:
                kept = self.spool.reject(path, f"unreadable: {unreadable.message}")
                self._summary.rejected += 1
                self._event(f"{self.rig_id}: {unreadable.message}; moved to {kept}")
                continue
            try:
                self._deliver(path, spooled.header, spooled.trace, lease_next=False)
                self._summary.resubmitted += 1
            except TraceRejected as refused:
                if refused.code in UNUSABLE and not self._report(
                        spooled.header.command_id, f"spooled command {spooled.header.command_id}",
                        f"trace rejected: {refused.code.name}: {refused.reason}", FailureKind.TRANSIENT, count=False):
                    return False
            except TracePending as pending:
                self._summary.error = pending
                return False
        return True

    def _run_command(self, measure: Measure, command: ProbeCommand, stop: Optional[threading.Event],
                     max_commands: int, on_progress: Optional[Callable[[r.JobProgress], None]]) -> Union[bool, Lease]:
        """Measures and submits one command. False: the run ends; a Lease: the next command."""
        summary = self._summary
        where = self._where(command)
        try:
            trace = measure(command)
        except RigFailure as failure:
            if not self._report(command.command_id, where, f"rig: {failure.reason}", failure.kind):
                return False
            if failure.stop:
                summary.error = SurfmapError(grpc.StatusCode.ABORTED, failure.reason, "driver")
                return False
            return True
        except Exception as bug:
            self._report(command.command_id, where, f"rig: driver raised {type(bug).__name__}: {bug}",
                         FailureKind.TRANSIENT)
            raise
        # Ask for the next command with this answer unless this is the last one
        # (decided after measuring: a stop during the probe counts): a lease
        # nobody executes holds its site until the lease expires.
        last = (stop is not None and stop.is_set()) or (max_commands > 0 and summary.executed + 1 >= max_commands)
        try:
            result = self.submit(command, trace, lease_next=not last)
        except TraceRejected as refused:
            if refused.code in UNUSABLE:
                return self._report(command.command_id, where, f"trace rejected: {refused.code.name}: {refused.reason}",
                                    FailureKind.TRANSIENT)
            summary.abandoned += 1
            return True
        except TracePending as pending:
            summary.error = pending
            return False
        except OSError as disk:
            # A rig that cannot keep its traces must not measure on: give the
            # site back and stop with the spool's error.
            self._report(command.command_id, where, f"rig cannot spool its trace: {disk}", FailureKind.TRANSIENT)
            summary.error = SurfmapError(grpc.StatusCode.INTERNAL, f"cannot spool the trace: {disk}", "spool")
            return False
        summary.accepted += 1
        if on_progress is not None:
            on_progress(result.progress)
        return result.next if result.next is not None else True


def run_rig(client: SurfmapClient, measure: Measure, rig_id: str, job_id: int = 0, *,
            spool_dir: Optional[Union[str, Path]] = None, retry_for_s: float = DEFAULT_RETRY_FOR_S,
            max_commands: int = 0, stop: Optional[threading.Event] = None,
            on_progress: Optional[Callable[[r.JobProgress], None]] = None,
            on_event: Optional[Callable[[str], None]] = None, frame: str = "object") -> RigSummary:
    """Runs ``measure`` as rig ``rig_id`` on ``job_id`` (0 = any running job)
    until the job ends: ``Rig(client, rig_id, spool_dir, retry_for_s,
    on_event=on_event).run(measure, job_id, max_commands, stop, on_progress)``,
    closing the rig afterwards. Returns the summary (``.error`` when it ended
    early; ``.raise_for_error()``).

    ``frame``: the frame ``measure``'s traces are in: "object" (the mesh's),
    "rig_base" or "rig_base_sensor_forces" (positions in the rig's base
    frame, forces in its F/T sensor's). A rig frame needs the rig registered
    to the object (``client.set_rig_registration``); ``command.rig_frame``
    then has the command in the base frame. A spooled trace is resubmitted
    in the frame (and with the registration) it was measured in."""
    with Rig(client, rig_id, spool_dir, retry_for_s, on_event=on_event, frame=frame) as rig:
        return rig.run(measure, job_id, max_commands, stop, on_progress)
