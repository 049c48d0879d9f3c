"""SimulatedArm: arm_driver.py's ArmHardware backed by the simulated rig, so
the driver skeleton runs end to end without a robot.

On ``prepare(command)`` it asks ``surfmap-rig simulate-drag --sim SCENE``
(the simulated rig as a driver program) for the drag trace of the command;
then, as the driver moves, touches down, drags and holds, it plays that trace
back as the hardware would report it: flange poses in the robot's base frame
and sensor readings in the sensor frame (the tool's weight included until the
sensor is biased). The driver's frame conversions therefore run for real
(tests/test_arm_driver.py checks that they give back the simulated rig's own
trace).
"""

from __future__ import annotations

from typing import List, Optional

import numpy as np

import surfmap_client as sc
from surfmap_client.driver_protocol import DriverProcess
from surfmap_client.local_processes import find_binary

from arm_hardware import Calibration, HardwareFault, RawSample, Recorder, unit


class SimulatedArm:
    """ArmHardware on the simulated rig (see the module's docstring)."""

    # The tool's weight in the base frame, N: seen by the sensor until it is biased.
    TOOL_WEIGHT_B = np.array([0.0, 0.0, -3.2])

    def __init__(self, scene: str, calibration: Calibration, rig_binary: Optional[str] = None) -> None:
        binary = find_binary("surfmap-rig", "SURFMAP_RIG", rig_binary)
        self.simulator = DriverProcess([binary, "simulate-drag", "--sim", scene])
        self.cal = calibration
        self.calls: List[str] = []            # every call, in order (tests check the abort path)
        self._command: Optional[sc.ProbeCommand] = None
        self._trace: Optional[sc.Trace] = None
        self._failure: Optional[sc.RigFailure] = None
        self._rotation = np.eye(3)            # flange axes in B
        self._position = np.zeros(3)          # flange in B, mm
        self._bias = np.zeros(3)              # subtracted from the sensor's readings
        self._clock = 1000.0                  # the controller's clock, s
        self._next_phase = sc.Phase.FORWARD

    def close(self) -> None:
        self.simulator.close()

    # ArmHardware
    def prepare(self, command: sc.ProbeCommand) -> None:
        self.calls.append("prepare")
        self._command = command
        self._next_phase = sc.Phase.FORWARD
        try:
            self._trace, self._failure = self.simulator.measure(command), None
        except sc.RigFailure as failure:  # the simulated rig cannot drag there
            self._trace, self._failure = None, failure

    def move_to(self, flange_position: np.ndarray, flange_rotation: np.ndarray, speed_mm_s: float) -> None:
        self.calls.append("move_to")
        self._position = np.asarray(flange_position, dtype=float)
        self._rotation = np.asarray(flange_rotation, dtype=float)

    def bias_sensor(self) -> None:
        self.calls.append("bias_sensor")
        self._bias = self._sensor_reading(np.zeros(3))  # free air: only the tool's weight

    def touch_down(self, direction: np.ndarray, force_n: float, max_travel_mm: float) -> None:
        self.calls.append("touch_down")
        if self._failure is not None:
            raise self._failure
        if self._trace is None:
            raise HardwareFault("touch_down before prepare")

    def drag(self, direction: np.ndarray, length_mm: float, speed_mm_s: float, phase: sc.Phase,
             record: Recorder) -> None:
        self.calls.append(f"drag {phase.name.lower()}")
        self._play(phase, record)

    def hold(self, seconds: float, record: Recorder) -> None:
        self.calls.append("hold")
        self._play(sc.Phase.PAUSE, record)

    def retract(self, direction: np.ndarray, distance_mm: float, speed_mm_s: float) -> None:
        self.calls.append("retract")
        self._position = self._position + distance_mm * unit(direction)

    def stop(self) -> None:
        self.calls.append("stop")

    # The playback
    def _sensor_reading(self, force_on_tip_b: np.ndarray) -> np.ndarray:
        """What the sensor reads (in S, before the bias) for a contact force in B."""
        sensor_axes_b = self._rotation @ self.cal.sensor_in_flange
        return self.cal.sensor_force_sign * sensor_axes_b.T @ (force_on_tip_b + self.TOOL_WEIGHT_B)

    def _play(self, phase: sc.Phase, record: Recorder) -> None:
        if self._trace is None or self._command is None:
            raise HardwareFault("motion in contact before prepare/touch_down")
        if phase != self._next_phase:
            raise HardwareFault(f"{phase.name.lower()} motion out of order (expected {self._next_phase.name.lower()})")
        self._next_phase = sc.Phase(int(phase) + 1) if phase != sc.Phase.REVERSE else sc.Phase.FORWARD
        trace, cal = self._trace, self.cal
        normal_o = unit(self._command.normal)
        indices = np.flatnonzero(trace.phase == phase)
        for i in indices:
            tip_centre_b = cal.rotation @ (trace.xyz[i] + cal.tip_radius_mm * normal_o) + cal.translation
            self._position = tip_centre_b - self._rotation @ cal.tip_in_flange
            reading = self._sensor_reading(cal.rotation @ trace.f[i]) - self._bias
            record(RawSample(self._clock + float(trace.t[i]), self._position.copy(), self._rotation.copy(), reading))
        if phase == sc.Phase.REVERSE:
            self._clock += float(trace.t[-1]) + 1.0
