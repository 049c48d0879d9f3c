"""The arm driver skeleton (examples/arm_driver.py) on the simulated "hardware":
its frames and safety limits in process, and whole maps of the plate through
the Python rig loop and through `surfmap-rig --driver`, both against the real
server and scored against the scene's truth."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path
from typing import List

import numpy as np
import pytest

import surfmap_client as sc
from surfmap_client.driver_protocol import DriverProcess
from surfmap_client.local_processes import score_map
from surfmap_client.records import ProbeParameters

from conftest import SCENE

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))

import arm_driver  # noqa: E402  (examples/ is not a package)
from simulated_arm import SimulatedArm  # noqa: E402


def plate_command(command_id: int = 4242, position=(20.0, -10.0, 0.0), speed: float = 10.0,
                  force: float = 5.0) -> sc.ProbeCommand:
    """A command on the plate's top face (z = 0, normal +z)."""
    return sc.ProbeCommand(command_id, 1, 0, 0, np.array(position, dtype=float), np.array([0.0, 0.0, 1.0]),
                           np.array([0.6, 0.8, 0.0]), ProbeParameters(20.0, speed, force), 1, None)


@pytest.fixture(scope="module")
def arm(lab):
    hardware = SimulatedArm(SCENE, arm_driver.CALIBRATION, rig_binary=lab.rig)
    yield hardware
    hardware.close()


@pytest.fixture(scope="module")
def simulator(lab):
    with DriverProcess([lab.rig, "simulate-drag", "--sim", SCENE]) as process:
        yield process


def test_the_frames_round_trip_to_the_simulated_rigs_own_trace(arm, simulator):
    """The arm reports flange poses in the base frame and forces in the (turned)
    sensor frame with the tool's weight; the driver must give back the
    simulated rig's contact points and surface forces in the object frame."""
    driver = arm_driver.ArmDriver(arm)
    command = plate_command()
    trace = driver.measure(command)
    truth = simulator.measure(command)
    assert np.allclose(trace.t, truth.t - truth.t[0], atol=1e-9)
    assert np.allclose(trace.xyz, truth.xyz, atol=1e-9)
    assert np.allclose(trace.f, truth.f, atol=1e-9)
    assert trace.phase.tolist() == truth.phase.tolist()
    # The push test: the surface pushes the tip out of the surface.
    assert np.mean(trace.f @ command.normal) == pytest.approx(5.0, rel=0.1)
    assert arm.calls[-8:] == ["prepare", "move_to", "bias_sensor", "touch_down", "drag forward", "hold",
                              "drag reverse", "retract"]


def test_a_wrongly_signed_sensor_shows_in_the_push_test(lab):
    """The hardware's sensor reports the reaction; a driver calibrated with
    the default sign gets forces pointing into the surface."""
    reaction = dataclasses.replace(arm_driver.CALIBRATION, sensor_force_sign=-1.0)
    hardware = SimulatedArm(SCENE, reaction, rig_binary=lab.rig)
    try:
        wrong = arm_driver.ArmDriver(hardware, arm_driver.CALIBRATION).measure(plate_command())
        right = arm_driver.ArmDriver(hardware, reaction).measure(plate_command())
    finally:
        hardware.close()
    assert np.mean(wrong.f[:, 2]) < 0 < np.mean(right.f[:, 2])


@pytest.mark.parametrize("command, limits, message", [
    (plate_command(speed=50.0), arm_driver.SafetyLimits(),
     "drag speed 50 mm/s is above this arm's cap of 30 mm/s"),
    (plate_command(force=20.0), arm_driver.SafetyLimits(),
     "normal force 20 N is above this arm's limit of 10 N"),
    (plate_command(), arm_driver.SafetyLimits(workspace_max=np.array([450.0, 350.0, 400.0])),
     "approach point ["),
])
def test_what_the_arm_can_never_do_is_unreachable_before_it_moves(arm, command, limits, message):
    before = len(arm.calls)
    with pytest.raises(sc.RigFailure) as failure:
        arm_driver.ArmDriver(arm, limits=limits).measure(command)
    assert failure.value.kind == sc.FailureKind.UNREACHABLE
    assert failure.value.reason.startswith(message), failure.value.reason
    assert len(arm.calls) == before, "no motion for a command the arm refuses"


def test_the_force_ceiling_takes_the_abort_path(arm):
    # The touch-down overshoots the commanded 5 N by up to 30 %: a 5.5 N ceiling trips.
    log: List[str] = []
    driver = arm_driver.ArmDriver(arm, limits=arm_driver.SafetyLimits(max_force_n=5.5), log=log.append)
    with pytest.raises(sc.RigFailure) as failure:
        driver.measure(plate_command(command_id=4243))
    assert failure.value.kind == sc.FailureKind.TRANSIENT
    assert failure.value.reason.startswith("force ceiling 5.5 N exceeded (")
    assert arm.calls[-2:] == ["stop", "retract"]
    assert log == []


def test_a_site_the_simulated_rig_cannot_drag_is_passed_on_with_its_kind(arm):
    far_off = plate_command(command_id=4244, position=(20.0, -10.0, 40.0))  # 40 mm above the plate
    with pytest.raises(sc.RigFailure) as failure:
        arm_driver.ArmDriver(arm).measure(far_off)
    assert failure.value.kind == sc.FailureKind.UNREACHABLE
    assert failure.value.reason.startswith("simulated rig: ")
    assert arm.calls[-2:] == ["stop", "retract"]


def map_job(client, lab, name: str) -> sc.JobInfo:
    obj = client.upload_object(lab.mesh(), name=name)
    return client.create_job(obj.object_id, "friction", "adaptive", finest_level=1, threshold=2.0, seed=5)


def check_map(client, lab, job_id: int, rig_id: str, tmp_path: Path) -> dict:
    done = client.get_job(job_id)
    assert done.state == sc.JobState.COMPLETED
    assert done.progress.measured > 99 and done.progress.failed == 0
    assert {s.rig_id for s in client.list_samples(job_id)} == {rig_id}
    map_path = tmp_path / "map.json"
    sc.write_map_file(client.get_map(job_id), str(map_path))
    score = score_map(lab.rig, SCENE, str(map_path))
    # The accuracy of `surfmap-rig --sim plate` (RMSE 0.025-0.027, 90-95 % over
    # different seeds). The frames are checked by the round-trip test above:
    # mu comes from the angle between the two passes' forces, which no
    # rotation of the force frame changes.
    assert score["mu_rmse"] < 0.045, score
    assert score["classification_accuracy"] > 0.85, score
    return score


def test_the_python_rig_loop_maps_the_plate_with_the_arm_driver(server, client, lab, tmp_path):
    job = map_job(client, lab, "plate-arm-python")
    result = subprocess.run([sys.executable, str(EXAMPLES / "arm_driver.py"), "--simulate", SCENE, "--rig", lab.rig,
                             "--server", server.address, "--job", str(job.job_id), "--rig-id", "arm-python",
                             "--spool", str(tmp_path / "spool")],
                            capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.startswith("arm-python: ") and "job finished" in result.stdout
    check_map(client, lab, job.job_id, "arm-python", tmp_path)
    assert not (tmp_path / "spool").exists()


def test_surfmap_rig_runs_the_arm_driver_as_its_external_driver(server, client, lab, tmp_path):
    job = map_job(client, lab, "plate-arm-external")
    driver = f"{sys.executable} {EXAMPLES / 'arm_driver.py'} --simulate {SCENE} --rig {lab.rig} --stdio"
    result = subprocess.run([lab.rig, "--server", server.address, "--job", str(job.job_id), "--rig-id", "arm-external",
                             "--spool", str(tmp_path / "spool"), "--quiet", "--driver", driver],
                            capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "arm-external driver ready: arm_driver.py on SimulatedArm (plate)" in result.stderr
    assert "arm-external driver exited with code 0" in result.stderr
    assert "job finished" in result.stdout
    check_map(client, lab, job.job_id, "arm-external", tmp_path)


def test_without_simulate_the_skeleton_says_what_to_do(tmp_path):
    result = subprocess.run([sys.executable, str(EXAMPLES / "arm_driver.py"), "--stdio"], capture_output=True,
                            text=True, timeout=60, input="")
    assert result.returncode == 2
    assert result.stderr.startswith("arm_driver: YourArm is a skeleton: implement its methods for your robot")
