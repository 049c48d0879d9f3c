"""The Python rig against the real surfmapd: lease, submit (spooled, retried,
refusals kept), report_failure with kinds, run_rig mapping a scene with the
simulated rig as the "hardware", and a server killed under a waiting rig."""

from __future__ import annotations

import struct
import subprocess
import threading
from pathlib import Path
from typing import List

import grpc
import numpy as np
import pytest

import surfmap_client as sc
from surfmap_client.driver_protocol import DriverProcess
from surfmap_client._stubs import pb
from surfmap_client.local_processes import LocalServer

from conftest import SCENE


@pytest.fixture(scope="module")
def simulator(lab):
    """The simulated rig on the plate as a driver program (surfmap-rig simulate-drag)."""
    with DriverProcess([lab.rig, "simulate-drag", "--sim", SCENE]) as process:
        yield process


@pytest.fixture()
def plate(client, lab) -> sc.ObjectInfo:
    return client.upload_object(lab.mesh(), name="plate-rig")


def uniform_job(client, plate, budget: int = 0, lease_s: float = 60.0) -> sc.JobInfo:
    return client.create_job(plate.object_id, "friction", "uniform", finest_level=0, budget=budget, lease_s=lease_s)


def lease_command(rig: sc.Rig, job_id: int) -> sc.ProbeCommand:
    """The next command of the job (one must be ready)."""
    lease = rig.lease(job_id)
    assert lease.command is not None, lease
    return lease.command


def bits(values) -> List[bytes]:
    return [struct.pack("<d", float(v)) for v in np.asarray(values, dtype=float).ravel()]


def files(directory: Path) -> List[str]:
    return sorted(p.name for p in directory.iterdir()) if directory.exists() else []


def test_lease_submit_and_an_identical_retry(client, plate, simulator, tmp_path):
    job = uniform_job(client, plate, budget=2)
    events: List[str] = []
    with sc.Rig(client, "py-rig-basics", tmp_path / "spool", on_event=events.append) as rig:
        lease = rig.lease(job.job_id)
        assert lease.command is not None and not lease.job_finished
        command = lease.command
        assert command.job_id == job.job_id and command.attempt == 1
        assert command.probe.segment_length_mm == pytest.approx(20.0)
        assert abs(np.linalg.norm(command.normal) - 1.0) < 1e-9
        trace = simulator.measure(command)
        result = rig.submit(command, trace, lease_next=True)
        assert not result.already_accepted
        assert result.sample.command_id == command.command_id
        assert result.sample.rig_id == "py-rig-basics"
        assert result.sample.fit is not None and 0.0 < result.sample.fit.friction.mu < 1.5
        assert result.progress.measured == 1
        assert result.next is not None and result.next.command is not None, "lease_next leased the next command"
        assert rig.spool.pending() == []
        # The same samples again (a retry whose first answer was lost): OK, nothing stored twice.
        again = rig.submit(command, trace)
        assert again.already_accepted
        assert again.sample.trace_id == result.sample.trace_id
        stored = client.get_trace(result.sample.trace_id)
        assert (bits(stored.t), bits(stored.xyz), bits(stored.f)) == (bits(trace.t), bits(trace.xyz), bits(trace.f))
        assert rig.spool.pending() == [] and files(rig.spool.rejected_dir) == []
    assert not (tmp_path / "spool").exists(), "an empty spool is removed when the rig closes"


def test_refusals_are_kept_with_their_reason_and_never_sent_when_invalid(client, plate, simulator, tmp_path):
    job = uniform_job(client, plate, budget=3)
    with sc.Rig(client, "py-rig-refusals", tmp_path / "spool", on_event=lambda line: None) as rig:
        command = lease_command(rig, job.job_id)
        trace = simulator.measure(command)
        rig.submit(command, trace)
        # Other samples for the answered command.
        other = sc.measured_trace(command, trace.t, trace.xyz, trace.f * 1.01, trace.phase)
        with pytest.raises(sc.TraceRejected) as refused:
            rig.submit(command, other)
        assert refused.value.code == grpc.StatusCode.ALREADY_EXISTS
        assert refused.value.path is not None and refused.value.path.parent == rig.spool.rejected_dir
        reason = Path(str(refused.value.path) + ".reason").read_text()
        assert reason.startswith("SubmitTrace: ALREADY_EXISTS: ")
        assert "already has trace" in reason
        assert "py-rig-refusals" in reason
        # A trace with a NaN force is never sent; it is kept with the problem.
        second = lease_command(rig, job.job_id)
        broken = simulator.measure(second)
        broken.f[5, 2] = float("nan")
        with pytest.raises(sc.TraceRejected) as invalid:
            rig.submit(second, broken)
        assert invalid.value.code == grpc.StatusCode.INVALID_ARGUMENT
        assert invalid.value.message.startswith("invalid trace: trace: f[5, 2] is not finite; trace kept in ")
        assert Path(str(invalid.value.path) + ".reason").read_text().startswith(
            "not submitted: the trace is invalid: trace: f[5, 2] is not finite")
        assert rig.spool.pending() == []
        assert len(files(rig.spool.rejected_dir)) == 4


def failure_events(client: sc.SurfmapClient, job_id: int) -> List[dict]:
    """The job's probe_failed events (the reason, kind and rig the server recorded)."""
    return [e.detail or {} for e in client.list_job_events(job_id) if e.kind == "probe_failed"]


def test_report_failure_kinds(client, plate, tmp_path):
    job = client.create_job(plate.object_id, "friction", "uniform", finest_level=0, budget=4, max_retries=2)
    with sc.Rig(client, "py-rig-failures", tmp_path / "spool", on_event=lambda line: None) as rig:
        transient = lease_command(rig, job.job_id)
        assert rig.report_failure(transient, "force ceiling 15 N exceeded", kind="transient") is True
        unreachable = lease_command(rig, job.job_id)
        rig.report_failure(unreachable, "outside the workspace box", sc.FailureKind.UNREACHABLE)
        recorded = [(e["command_id"], e["kind"], e["reason"], e["rig"]) for e in failure_events(client, job.job_id)]
        assert recorded == [(transient.command_id, "transient", "force ceiling 15 N exceeded", "py-rig-failures"),
                            (unreachable.command_id, "unreachable", "outside the workspace box", "py-rig-failures")]
        plan = client.get_plan(job.job_id)
        site = next(s for s in plan.sites if (s.level, s.vertex) == (unreachable.level, unreachable.vertex))
        assert "outside the workspace box" in site.failure_reason
        with pytest.raises(sc.SurfmapError) as bad_kind:
            rig.report_failure(transient, "x", kind="sometimes")
        assert bad_kind.value.code == grpc.StatusCode.INVALID_ARGUMENT
        assert bad_kind.value.message == "kind must be 'transient' or 'unreachable', got 'sometimes'"
        with pytest.raises(sc.SurfmapError) as not_leased:
            rig.report_failure(unreachable, "again")
        assert not_leased.value.code == grpc.StatusCode.FAILED_PRECONDITION


def test_run_rig_maps_the_plate_with_the_simulated_rig(client, plate, simulator, tmp_path):
    job = client.create_job(plate.object_id, "friction", "adaptive", finest_level=1, threshold=2.0, seed=11)
    progress: List[int] = []
    summary = sc.run_rig(client, simulator.measure, "py-rig-map", job.job_id, spool_dir=tmp_path / "spool",
                         on_progress=lambda p: progress.append(p.measured), on_event=lambda line: None)
    summary.raise_for_error()
    done = client.get_job(job.job_id)
    assert done.state == sc.JobState.COMPLETED
    assert summary.job_finished and summary.accepted == done.progress.measured > 99
    assert (summary.failures, summary.abandoned, summary.rejected, summary.spooled_left) == (0, 0, 0, 0)
    assert progress == sorted(progress) and progress[-1] == done.progress.measured
    assert {s.rig_id for s in client.list_samples(job.job_id)} == {"py-rig-map"}
    assert summary.format("py-rig-map").startswith(f"py-rig-map: {summary.accepted} commands done, 0 failures")


def test_run_reports_driver_failures_with_their_kind_and_stops_on_a_bug(client, plate, simulator, tmp_path):
    job = client.create_job(plate.object_id, "friction", "uniform", finest_level=0, budget=6, max_retries=1)
    calls: List[int] = []

    def measure(command: sc.ProbeCommand) -> sc.Trace:
        calls.append(command.command_id)
        if len(calls) == 1:
            raise sc.RigFailure("outside the workspace box", kind="unreachable")
        if len(calls) == 3:
            raise ZeroDivisionError("a bug in the driver")
        return simulator.measure(command)

    events: List[str] = []
    with sc.Rig(client, "py-rig-kinds", tmp_path / "spool", on_event=events.append) as rig:
        with pytest.raises(ZeroDivisionError):
            rig.run(measure, job.job_id)
    plan = client.get_plan(job.job_id)
    reasons = sorted(s.failure_reason for s in plan.sites if s.failure_reason)
    assert any("rig: outside the workspace box" in reason for reason in reasons), reasons
    assert any("rig: driver raised ZeroDivisionError: a bug in the driver" in reason for reason in reasons), reasons
    assert plan.progress.measured == 1
    assert plan.progress.leased == 0, "the command the bug interrupted was given back"
    assert [e["kind"] for e in failure_events(client, job.job_id)] == ["unreachable", "transient"]
    assert any("failed (unreachable" in line for line in events), events


def test_a_stop_event_finishes_the_probe_and_leaves_no_lease_behind(client, plate, simulator, tmp_path):
    job = uniform_job(client, plate, budget=6)
    stop = threading.Event()
    measured: List[int] = []

    def measure(command: sc.ProbeCommand) -> sc.Trace:
        measured.append(command.command_id)
        if len(measured) == 2:
            stop.set()  # e.g. SIGINT while the second probe runs
        return simulator.measure(command)

    summary = sc.run_rig(client, measure, "py-rig-stop", job.job_id, spool_dir=tmp_path / "spool", stop=stop,
                         on_event=lambda line: None)
    assert summary.stopped and summary.error is None
    assert summary.accepted == 2 == len(measured), "the probe under way was finished and delivered"
    progress = client.get_job(job.job_id).progress
    assert (progress.measured, progress.leased) == (2, 0)


def test_max_commands_asks_for_no_lease_it_will_not_use(client, plate, simulator, tmp_path):
    job = uniform_job(client, plate, budget=6)
    summary = sc.run_rig(client, simulator.measure, "py-rig-max", job.job_id, spool_dir=tmp_path / "spool",
                         max_commands=3, on_event=lambda line: None)
    assert summary.reached_max_commands and summary.accepted == 3
    progress = client.get_job(job.job_id).progress
    assert (progress.measured, progress.leased) == (3, 0)


def test_a_stop_failure_ends_the_run(client, plate, tmp_path):
    job = uniform_job(client, plate, budget=3)

    def measure(command: sc.ProbeCommand) -> sc.Trace:
        raise sc.RigFailure("emergency stop pressed", stop=True)

    summary = sc.run_rig(client, measure, "py-rig-estop", job.job_id, spool_dir=tmp_path / "spool",
                         on_event=lambda line: None)
    assert summary.error is not None and summary.error.code == grpc.StatusCode.ABORTED
    assert summary.failures == 1
    with pytest.raises(sc.SurfmapError, match="emergency stop pressed"):
        summary.raise_for_error()


def test_a_python_spool_file_is_resubmitted_by_surfmap_rig(client, plate, simulator, lab, tmp_path):
    """The two rigs share the spool format: surfmap-rig delivers a trace a Python rig spooled."""
    job = uniform_job(client, plate, budget=2)
    spool_dir = tmp_path / "shared-spool"
    with sc.Rig(client, "shared-rig", spool_dir, on_event=lambda line: None) as rig:
        command = lease_command(rig, job.job_id)
        trace = simulator.measure(command)
        header = sc.spool.SpoolHeader(command.command_id, command.job_id, command.attempt, "shared-rig", 1000)
        rig.spool.add(header, trace)  # as if the Python rig crashed before submitting
    result = subprocess.run([lab.rig, "--server", client.address, "--sim", SCENE, "--job", str(job.job_id),
                             "--rig-id", "shared-rig", "--spool", str(spool_dir), "--quiet"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "1 spooled trace resubmitted" in result.stdout
    sample = next(s for s in client.list_samples(job.job_id) if s.command_id == command.command_id)
    stored = client.get_trace(sample.trace_id)
    assert (bits(stored.t), bits(stored.xyz), bits(stored.f)) == (bits(trace.t), bits(trace.xyz), bits(trace.f))
    assert not spool_dir.exists()


@pytest.fixture()
def own_server(lab, tmp_path):
    """A server of this test alone (it is stopped and restarted on the same port)."""
    server = LocalServer(lab.surfmapd, str(tmp_path / "own.db"), str(tmp_path / "own.log")).start()
    yield server
    server.stop()


def test_a_rig_waits_out_a_restart_and_keeps_what_it_could_not_deliver(lab, own_server, simulator, tmp_path):
    with sc.connect(own_server.address, timeout=5.0) as client:
        plate = client.upload_object(lab.mesh(), name="plate-restart")
        job = client.create_job(plate.object_id, "friction", "uniform", finest_level=0, budget=3)
        events: List[str] = []
        with sc.Rig(client, "py-rig-restart", tmp_path / "spool", retry_for_s=30.0, on_event=events.append) as rig:
            # 1. The server is killed and back within the retry time: the submission goes through.
            first = lease_command(rig, job.job_id)
            first_trace = simulator.measure(first)
            own_server.kill()
            restarter = threading.Timer(1.0, own_server.restart)
            restarter.start()
            result = rig.submit(first, first_trace)
            restarter.join()
            assert result.sample.command_id == first.command_id
            assert any(line.startswith("py-rig-restart: server unavailable, retrying for ") for line in events), events
            assert rig.spool.pending() == []

            # 2. Down for longer than the retry time: the trace stays in the spool ...
            rig.retry_for_s = 1.0
            second = lease_command(rig, job.job_id)
            second_trace = simulator.measure(second)
            own_server.kill()
            with pytest.raises(sc.TracePending) as pending:
                rig.submit(second, second_trace)
            assert pending.value.code == grpc.StatusCode.UNAVAILABLE
            assert rig.spool.pending() == [pending.value.path]
            assert any("gave up after retrying for 1.0 s" in line for line in events), events
            # ... and is delivered when the server is back.
            own_server.restart()
            summary = rig.resubmit_spool()
            assert (summary.resubmitted, summary.spooled_left, summary.error) == (1, 0, None)
        samples = {s.command_id: s for s in client.list_samples(job.job_id)}
        assert set(samples) == {first.command_id, second.command_id}
        stored = client.get_trace(samples[second.command_id].trace_id)
        assert bits(stored.f) == bits(second_trace.f)


# ---------------------------------------------------------------- frames and calibration

def rotation_matrix(wxyz) -> np.ndarray:
    w, x, y, z = wxyz
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


POSE_WXYZ = np.array([0.9, 0.1, -0.3, 0.3]) / np.linalg.norm([0.9, 0.1, -0.3, 0.3])
POSE_T = np.array([380.0, 90.0, -40.0])
SENSOR_WXYZ = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])  # 90 deg about z


def to_rig_frame(trace: sc.Trace, sensor_forces: bool = True) -> sc.Trace:
    """An object-frame trace as the registered rig records it: positions in its
    base frame, forces in its sensor's (f_sensor = S^T R f)."""
    R, S = rotation_matrix(POSE_WXYZ), rotation_matrix(SENSOR_WXYZ)
    xyz = np.asarray(trace.xyz) @ R.T + POSE_T
    f = np.asarray(trace.f) @ R.T
    if sensor_forces:
        f = f @ S  # (S^T f^T)^T
    return sc.Trace(trace.trace_id, trace.command_id, trace.job_id, np.asarray(trace.t), xyz, f,
                    np.asarray(trace.phase))


def test_run_rig_in_the_rig_frame(client, plate, simulator, tmp_path):
    rig_id = "py-rig-frame"
    reg = client.set_rig_registration(plate.object_id, rig_id, POSE_WXYZ, POSE_T, tip_radius_mm=2.0,
                                      sensor_rotation_wxyz=SENSOR_WXYZ)
    assert reg["version"] == 1 and reg["tip_radius_mm"] == 2.0
    assert client.get_rig_registration(object_id=plate.object_id, rig_name=rig_id)["registration_id"] == \
        reg["registration_id"]
    with pytest.raises(sc.SurfmapError) as bad:
        client.set_rig_registration(plate.object_id, rig_id, [1, 0, 0, 0.5], POSE_T)
    assert bad.value.code == grpc.StatusCode.INVALID_ARGUMENT and "not a unit quaternion" in bad.value.message

    job = uniform_job(client, plate, budget=4)
    seen: List[sc.ProbeCommand] = []

    def measure(command: sc.ProbeCommand) -> sc.Trace:
        seen.append(command)
        return to_rig_frame(simulator.measure(command))

    summary = sc.run_rig(client, measure, rig_id, job.job_id, spool_dir=tmp_path / "spool",
                         on_event=lambda line: None, frame="rig_base_sensor_forces")
    summary.raise_for_error()
    assert summary.accepted == 4 and summary.rejected == 0
    R = rotation_matrix(POSE_WXYZ)
    for command in seen:
        assert command.rig_frame is not None and command.rig_frame.registration_id == reg["registration_id"]
        np.testing.assert_allclose(command.rig_frame.position, R @ command.position + POSE_T, atol=1e-9)
        np.testing.assert_allclose(command.rig_frame.normal, R @ command.normal, atol=1e-9)
        assert command.rig_frame.tool_centre_path.shape[0] >= 15
    assert all(0.05 < s.fit.friction.mu < 1.0 for s in client.list_samples(job.job_id))

    # The same rig-frame data stated as the object's frame: refused, naming the frame.
    job2 = uniform_job(client, plate, budget=1)
    with sc.Rig(client, rig_id, tmp_path / "spool2", on_event=lambda line: None) as rig:
        command = lease_command(rig, job2.job_id)
        with pytest.raises(sc.TraceRejected) as refused:
            rig.submit(command, to_rig_frame(simulator.measure(command), sensor_forces=False))
    assert refused.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "implausible trace: frame: the trace looks like it is in the rig's base frame" in str(refused.value)


def test_a_spooled_rig_frame_trace_is_resubmitted_in_its_frame(client, plate, simulator, lab, tmp_path):
    """A trace spooled by a rig-frame run keeps its frame and registration: a
    later object-frame run (Python, then surfmap-rig) resubmits it as it was measured."""
    rig_id = "py-rig-frame-spool"
    reg = client.set_rig_registration(plate.object_id, rig_id, POSE_WXYZ, POSE_T, tip_radius_mm=2.0,
                                      sensor_rotation_wxyz=SENSOR_WXYZ)
    job = uniform_job(client, plate, budget=2)
    spool_dir = tmp_path / "spool"
    traces = {}

    def spool_one(measured_ms: int) -> None:
        """Leases and measures in the rig's frame, as if the rig crashed before submitting."""
        with sc.Rig(client, rig_id, spool_dir, on_event=lambda line: None, frame="rig_base_sensor_forces") as rig:
            command = lease_command(rig, job.job_id)
            assert command.rig_frame is not None
            traces[command.command_id] = to_rig_frame(simulator.measure(command))
            header = sc.spool.SpoolHeader(command.command_id, command.job_id, command.attempt, rig_id, measured_ms,
                                          "rig_base_sensor_forces", command.rig_frame.registration_id)
            rig.spool.add(header, traces[command.command_id])

    spool_one(1000)
    with sc.Rig(client, rig_id, spool_dir, on_event=lambda line: None) as rig:  # this run's frame: the object's
        summary = rig.resubmit_spool()
    assert (summary.resubmitted, summary.rejected, summary.error) == (1, 0, None)
    spool_one(2000)
    result = subprocess.run([lab.rig, "--server", client.address, "--sim", SCENE, "--job", str(job.job_id),
                             "--rig-id", rig_id, "--spool", str(spool_dir), "--quiet"],  # no --frame: the object's
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "1 spooled trace resubmitted" in result.stdout
    samples = {s.command_id: s for s in client.list_samples(job.job_id)}
    assert set(samples) == set(traces)
    for command_id, trace in traces.items():
        stored = client._traces.GetTrace(pb.GetTraceRequest(trace_id=samples[command_id].trace_id))
        assert (stored.frame, stored.registration_id) == (pb.TRACE_FRAME_RIG_BASE_SENSOR_FORCES,
                                                          reg["registration_id"])
        assert bits(stored.samples.fx) == bits(np.asarray(trace.f)[:, 0])
