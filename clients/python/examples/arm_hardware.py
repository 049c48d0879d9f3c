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
    """What the driver needs from the arm and the sensor. Every motion blocks
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
    """Your robot: implement each method with your arm's and sensor's API.

    For example with a Universal Robots e-series arm through ur_rtde and a
    wrist sensor streaming over UDP/EtherCAT:
      move_to      RTDEControlInterface.moveL(pose, speed) (pose: mm -> m, rotation -> rotation vector)
      bias_sensor  the sensor's bias/tare command (or average 0.2 s of readings and subtract)
      touch_down   forceMode along -normal with a small speed limit, stop when |F . n| >= force_n
      drag         keep forceMode on the normal axis and servo the tangential axis
                   (speedL / servoL), reading getActualTCPPose and the sensor at >= 100 Hz
                   and calling record(RawSample(...)) for each reading
      hold         the same with zero tangential speed for `seconds`
      retract      forceModeStop, then moveL up
      stop         forceModeStop + stopL (and your own protective stop)
    """

    def __init__(self) -> None:
        raise NotImplementedError("YourArm is a skeleton: implement its methods for your robot (see the comments "
                                  "in arm_driver.py), or run with --simulate SCENE")
