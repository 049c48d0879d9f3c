"""The hardware side of arm_driver.py: the frames' calibration, what a
reading is, the interface the driver needs from an arm and its force/torque
sensor (ArmHardware), and the skeleton to fill in for your robot (YourArm).
SimulatedArm (simulated_arm.py) implements the same interface on the
simulated rig.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

import surfmap_client as sc


def unit(v: np.ndarray) -> np.ndarray:
    return np.asarray(v, dtype=float) / np.linalg.norm(v)


@dataclass(frozen=True)
class Calibration:
    """Where the object, the tip and the sensor are (the frames of arm_driver.py's docstring)."""

    base_from_object: np.ndarray      # (4, 4) T_B_O: object frame -> robot base frame, mm
    tip_in_flange: np.ndarray         # (3,) tip sphere centre in the flange frame, mm
    sensor_in_flange: np.ndarray      # (3, 3) rotation R_F_S: sensor axes -> flange frame
    tip_radius_mm: float
    sensor_force_sign: float = 1.0    # -1 for a sensor that reports the reaction force

    @property
    def rotation(self) -> np.ndarray:
        return self.base_from_object[:3, :3]

    @property
    def translation(self) -> np.ndarray:
        return self.base_from_object[:3, 3]


# --------------------------------------------------------------------------- the hardware interface


@dataclass(frozen=True)
class RawSample:
    """One reading while recording, in the robot's terms."""

    t: float                        # s, the controller's clock
    flange_position: np.ndarray     # (3,) mm, in B
    flange_rotation: np.ndarray     # (3, 3) flange axes in B
    force_sensor: np.ndarray        # (3,) N, in S, biased


Recorder = Callable[[RawSample], None]


class HardwareFault(RuntimeError):
    """The arm or the sensor reports a fault (protective stop, lost contact, no contact found)."""


class ArmHardware(Protocol):
    """What the driver needs from the arm and the sensor (YourArm below is the
    skeleton to fill in, SimulatedArm the simulated one). Every motion blocks
    until done. `record` callbacks are called at the sensor's rate during a
    motion; if one raises, the motion must stop and the exception propagate."""

    def prepare(self, command: sc.ProbeCommand) -> None:
        """Hook before a probe (log it; the simulator needs it to simulate the drag)."""

    def move_to(self, flange_position: np.ndarray, flange_rotation: np.ndarray, speed_mm_s: float) -> None:
        """Position-controlled move of the flange to this pose (in B)."""

    def bias_sensor(self) -> None:
        """Zero the F/T sensor (in free air)."""

    def touch_down(self, direction: np.ndarray, force_n: float, max_travel_mm: float) -> None:
        """Guarded move along `direction` (unit, in B) until the force along it
        reaches `force_n`, then force control holding it. HardwareFault when
        there is no contact within `max_travel_mm`."""

    def drag(self, direction: np.ndarray, length_mm: float, speed_mm_s: float, phase: sc.Phase,
             record: Recorder) -> None:
        """Tangential move under force control, recording."""

    def hold(self, seconds: float, record: Recorder) -> None:
        """Stay in contact, still, recording (the pause)."""

    def retract(self, direction: np.ndarray, distance_mm: float, speed_mm_s: float) -> None:
        """Leave force control and move away along `direction` (unit, in B)."""

    def stop(self) -> None:
        """Abort: stop every motion now, leave force control."""


class YourArm:
    """Your robot: implement each method with your arm's and sensor's API,
    then delete the NotImplementedError of __init__.

    The notes name the calls for a Universal Robots e-series arm through
    ur_rtde (RTDEControlInterface `control`, RTDEReceiveInterface `receive`)
    and a wrist sensor streaming its wrench; other arms have the same pieces.
    Poses: mm and rotation matrices here, metres and rotation vectors in
    ur_rtde (convert at the call).
    """

    def __init__(self) -> None:
        raise NotImplementedError("YourArm is a skeleton: implement its methods for your robot (see the comments "
                                  "in arm_hardware.py), or run with --simulate SCENE")

    def prepare(self, command: sc.ProbeCommand) -> None:
        """Log the command (site, attempt) with your robot's own logs."""
        raise NotImplementedError

    def move_to(self, flange_position: np.ndarray, flange_rotation: np.ndarray, speed_mm_s: float) -> None:
        """control.moveL(pose, speed / 1000): a blocking linear move in free air."""
        raise NotImplementedError

    def bias_sensor(self) -> None:
        """The sensor's bias/tare command, or: average 0.2 s of readings and subtract them from now on."""
        raise NotImplementedError

    def touch_down(self, direction: np.ndarray, force_n: float, max_travel_mm: float) -> None:
        """control.forceMode(task frame, selection [0, 0, 1, 0, 0, 0] along `direction`, wrench force_n,
        limits): the arm moves along `direction` until it presses with force_n; watch receive's TCP
        pose and raise HardwareFault when it has travelled max_travel_mm without contact."""
        raise NotImplementedError

    def drag(self, direction: np.ndarray, length_mm: float, speed_mm_s: float, phase: sc.Phase,
             record: Recorder) -> None:
        """Keep forceMode on the normal axis; servo the tangential axis (control.speedL or servoL) at
        speed_mm_s for length_mm. Meanwhile, at >= 100 Hz (the RTDE loop runs at 500 Hz): read
        receive.getActualTCPPose() (flange pose) and the sensor's wrench with one timestamp and call
        record(RawSample(...)). Let an exception from record stop the motion and propagate."""
        raise NotImplementedError

    def hold(self, seconds: float, record: Recorder) -> None:
        """As drag with zero tangential speed for `seconds` (the pause), recording."""
        raise NotImplementedError

    def retract(self, direction: np.ndarray, distance_mm: float, speed_mm_s: float) -> None:
        """control.forceModeStop(), then a moveL of distance_mm along `direction`."""
        raise NotImplementedError

    def stop(self) -> None:
        """control.forceModeStop() and control.stopL(); trigger your protective stop if the arm does not obey."""
        raise NotImplementedError
