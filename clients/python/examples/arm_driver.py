#!/usr/bin/python3
"""A surfmap driver for a robot arm with a wrist force/torque sensor and a
spherical probe tip: the skeleton to adapt to your lab, runnable today
against the simulated rig.

    # the simulated "hardware" (SimulatedArm: the simulated rig behind the same calls)
    arm_driver.py --simulate plate --server 127.0.0.1:50051 --job 3        # Python rig loop (sc.run_rig)
    surfmap-rig --server 127.0.0.1:50051 --job 3 \\
        --driver "/usr/bin/python3 arm_driver.py --simulate plate --stdio" # surfmap-rig runs the loop

    # your robot: implement YourArm below, set CALIBRATION and LIMITS, drop --simulate

What is called where, per probe command (ArmDriver.measure):

  0. check the command against this arm's limits: speed cap, normal force,
     segment length, workspace box (RigFailure "unreachable" otherwise: this
     arm can never do it, the server gives the site to others or up)
  1. move, in position control, to the approach pose: tip centre
     `approach_mm` above the start of the drag, tool z axis along -normal,
     tool x axis along the drag direction
  2. bias the F/T sensor there, in free air (this removes the tool's weight
     at this orientation, which the drag keeps)
  3. touch down: a guarded move along -normal until the contact force
     reaches the commanded normal force, then hold it under force control
  4. record tip position and wrench at >= 100 Hz while dragging forward over
     `segment_length_mm` at `speed_mm_s` (force control keeps the normal
     force on the curved surface), pausing `pause_s`, dragging back
  5. retract along +normal; convert the recording to the object frame
  abort path (any fault, a force above the ceiling, a bug): stop the motion,
  leave force control, retract, and report a "transient" failure (the site
  is tried again later, maybe by another rig)

Frames (all lengths mm):

  object frame O   the frame of the mesh uploaded to surfmapd. Commands come
                   in O; traces go back in O.
  robot base B     T_B_O (CALIBRATION.base_from_object, 4x4) maps O to B:
                   from your calibration, e.g. touch >= 3 known points of the
                   object with the tip and fit the rigid transform (Kabsch).
  flange F         the arm reports the flange pose (position + rotation in B).
  tip centre       CALIBRATION.tip_in_flange: the centre of the spherical tip
                   in F (tool calibration, e.g. a four-point pivot).
  sensor S         CALIBRATION.sensor_in_flange: rotates sensor axes into F
                   (from the sensor's mounting drawing).
  contact point    surfmap wants the point where the tip touches the surface:
                   tip centre - r * n, with n the surface normal (the
                   command's; on a curved surface the true contact normal
                   turns slightly along the drag, which shifts both passes
                   alike and does not bias the fit).
  force            surfmap wants the force BY the surface ON the probe. A
                   sensor between flange and tool, biased in free air, reads
                   the force the tool puts on it, which for a static tool is
                   the force the surface puts on the tip. Sensors that report
                   the reaction need CALIBRATION.sensor_force_sign = -1. Push
                   test: press the tip towards the flange by hand; the force
                   in O must point out of the surface (along +normal).

Safety limits (LIMITS): a force ceiling checked on every recorded sample, a
workspace box in B for every planned tip position, a speed cap, a ceiling on
the commanded normal force, a touch-down that must find contact within a
travel, and the abort path above. Keep your robot's own protective limits
too: these are the driver's, not a replacement for the controller's.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from dataclasses import dataclass, field
from typing import Callable, List, Optional

import numpy as np

import surfmap_client as sc
from surfmap_client import driver_protocol

# Beside this file: the hardware interface and the simulated arm.
from arm_hardware import ArmHardware, Calibration, HardwareFault, RawSample, Recorder, YourArm, unit

# --------------------------------------------------------------------------- configuration


@dataclass(frozen=True)
class SafetyLimits:
    max_force_n: float = 15.0          # abort when |F| exceeds this on any sample
    max_normal_force_n: float = 10.0   # refuse commands asking for more (unreachable)
    max_speed_mm_s: float = 30.0       # refuse faster drags (unreachable)
    max_segment_mm: float = 60.0       # refuse longer drags (unreachable)
    workspace_min: np.ndarray = field(default_factory=lambda: np.array([200.0, -350.0, -50.0]))  # box in B, mm
    workspace_max: np.ndarray = field(default_factory=lambda: np.array([700.0, 350.0, 400.0]))
    approach_mm: float = 15.0          # stand-off above the surface before touch-down
    touchdown_travel_mm: float = 25.0  # no contact within this: abort (the object is not where O says)
    transit_speed_mm_s: float = 100.0  # for moves in free air
    pause_s: float = 0.5               # between the passes
    min_rate_hz: float = 100.0         # recording rate required


def rotation_z(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def transform(rotation: np.ndarray, translation) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


# An example set-up: the object 450 mm in front of the base, turned 30 degrees
# about z, on a table 20 mm above the base plane; a 60 mm probe along the
# flange's z axis with a 2 mm tip; the sensor turned 90 degrees about z.
CALIBRATION = Calibration(base_from_object=transform(rotation_z(30.0), [450.0, 0.0, 20.0]),
                          tip_in_flange=np.array([0.0, 0.0, 60.0]),
                          sensor_in_flange=rotation_z(90.0),
                          tip_radius_mm=2.0)
LIMITS = SafetyLimits()

# --------------------------------------------------------------------------- the driver


class ForceCeilingExceeded(HardwareFault):
    pass


def tool_rotation(normal_b: np.ndarray, drag_b: np.ndarray) -> np.ndarray:
    """Flange axes in B: z into the surface (-normal), x along the drag."""
    z = -unit(normal_b)
    x = unit(drag_b - np.dot(drag_b, z) * z)
    return np.column_stack([x, np.cross(z, x), z])


class ArmDriver:
    """Measures probe commands with an ArmHardware (see the module's docstring)."""

    def __init__(self, hardware: ArmHardware, calibration: Calibration = CALIBRATION,
                 limits: SafetyLimits = LIMITS, log: Callable[[str], None] = lambda line: None) -> None:
        self.hw = hardware
        self.cal = calibration
        self.limits = limits
        self.log = log

    # Object frame <-> base frame.
    def to_base(self, p_o: np.ndarray) -> np.ndarray:
        return self.cal.rotation @ p_o + self.cal.translation

    def direction_to_base(self, v_o: np.ndarray) -> np.ndarray:
        return self.cal.rotation @ v_o

    def measure(self, command: sc.ProbeCommand) -> sc.Trace:
        """One probe: the trace in the object frame, or RigFailure."""
        lim, cal = self.limits, self.cal
        p = command.probe
        # 0. What this arm can never do.
        if p.speed_mm_s > lim.max_speed_mm_s:
            raise sc.RigFailure(f"drag speed {p.speed_mm_s:g} mm/s is above this arm's cap of "
                                f"{lim.max_speed_mm_s:g} mm/s", kind="unreachable")
        if p.normal_force_n > lim.max_normal_force_n:
            raise sc.RigFailure(f"normal force {p.normal_force_n:g} N is above this arm's limit of "
                                f"{lim.max_normal_force_n:g} N", kind="unreachable")
        if p.segment_length_mm > lim.max_segment_mm:
            raise sc.RigFailure(f"drag of {p.segment_length_mm:g} mm is longer than this arm's "
                                f"{lim.max_segment_mm:g} mm", kind="unreachable")
        n_o = unit(command.normal)
        d_o = unit(command.drag_direction - np.dot(command.drag_direction, n_o) * n_o)
        half = p.segment_length_mm / 2.0
        start_o = command.position - half * d_o
        end_o = command.position + half * d_o
        n_b, d_b = self.direction_to_base(n_o), self.direction_to_base(d_o)
        centre = lambda contact_o: self.to_base(contact_o + cal.tip_radius_mm * n_o)  # noqa: E731
        approach_b = centre(start_o) + lim.approach_mm * n_b
        for name, point in (("approach", approach_b), ("drag start", centre(start_o)), ("drag end", centre(end_o)),
                            ("retract", centre(end_o) + lim.approach_mm * n_b)):
            if np.any(point < lim.workspace_min) or np.any(point > lim.workspace_max):
                raise sc.RigFailure(f"{name} point {np.round(point, 1).tolist()} mm (base frame) is outside the "
                                    "workspace box", kind="unreachable")
        rotation_b = tool_rotation(n_b, d_b)
        flange_at = lambda tip_centre_b: tip_centre_b - rotation_b @ cal.tip_in_flange  # noqa: E731

        # 1-5, with the abort path around every motion.
        samples: List[RawSample] = []
        phases: List[int] = []

        def recorder(phase: sc.Phase) -> Recorder:
            def record(sample: RawSample) -> None:
                magnitude = float(np.linalg.norm(sample.force_sensor))
                if magnitude > lim.max_force_n:
                    raise ForceCeilingExceeded(f"force ceiling {lim.max_force_n:g} N exceeded ({magnitude:.1f} N) "
                                               f"during the {phase.name.lower()} phase")
                samples.append(sample)
                phases.append(int(phase))
            return record

        self.hw.prepare(command)
        try:
            self.hw.move_to(flange_at(approach_b), rotation_b, lim.transit_speed_mm_s)
            self.hw.bias_sensor()
            self.hw.touch_down(-n_b, p.normal_force_n, lim.approach_mm + lim.touchdown_travel_mm)
            self.hw.drag(d_b, p.segment_length_mm, p.speed_mm_s, sc.Phase.FORWARD, recorder(sc.Phase.FORWARD))
            self.hw.hold(lim.pause_s, recorder(sc.Phase.PAUSE))
            self.hw.drag(-d_b, p.segment_length_mm, p.speed_mm_s, sc.Phase.REVERSE, recorder(sc.Phase.REVERSE))
            self.hw.retract(n_b, lim.approach_mm, lim.transit_speed_mm_s)
        except sc.RigFailure:
            self.abort(n_b)
            raise
        except HardwareFault as fault:
            self.abort(n_b)
            raise sc.RigFailure(str(fault), kind="transient") from None
        except BaseException:
            self.abort(n_b)  # a bug or Ctrl-C: the robot stops before anything else
            raise
        return self.to_trace(command, samples, phases, n_b)

    def abort(self, normal_b: np.ndarray) -> None:
        """Stop, leave force control, back off along the normal (best effort)."""
        try:
            self.hw.stop()
            self.hw.retract(normal_b, self.limits.approach_mm, self.limits.transit_speed_mm_s)
        except Exception as fault:  # the operator must look: say so loudly
            self.log(f"ABORT PATH FAILED, check the robot: {fault}")

    def to_trace(self, command: sc.ProbeCommand, samples: List[RawSample], phases: List[int],
                 normal_b: np.ndarray) -> sc.Trace:
        """The recording as surfmap's trace: contact point and force by the surface on the probe, in O."""
        cal = self.cal
        if len(samples) < 3:
            raise sc.RigFailure(f"only {len(samples)} samples recorded", kind="transient")
        t = np.array([s.t for s in samples])
        keep = np.concatenate([[True], np.diff(t) > 0])  # controllers repeat a timestamp now and then
        t, samples, phases = t[keep], [s for s, k in zip(samples, keep) if k], [ph for ph, k in zip(phases, keep) if k]
        rate = 1.0 / float(np.median(np.diff(t)))
        if rate < self.limits.min_rate_hz * 0.99:
            raise sc.RigFailure(f"recorded at {rate:.0f} Hz, below the {self.limits.min_rate_hz:g} Hz needed",
                                kind="transient")
        positions = np.array([s.flange_position for s in samples])
        rotations = np.array([s.flange_rotation for s in samples])
        forces_s = np.array([s.force_sensor for s in samples]) * cal.sensor_force_sign
        tip_centre_b = positions + np.einsum("nij,j->ni", rotations, cal.tip_in_flange)
        contact_b = tip_centre_b - cal.tip_radius_mm * normal_b
        force_b = np.einsum("nij,jk,nk->ni", rotations, cal.sensor_in_flange, forces_s)
        r_bo = cal.rotation
        contact_o = (contact_b - cal.translation) @ r_bo      # R^T (p - t), row-wise
        force_o = force_b @ r_bo
        return sc.measured_trace(command, t - t[0], contact_o, force_o, phases)


# --------------------------------------------------------------------------- running it


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--simulate", metavar="SCENE",
                        help="send the hardware calls to the simulated rig on this scene (surfmap-rig simulate-drag)")
    parser.add_argument("--rig", help="surfmap-rig binary, for --simulate (env SURFMAP_RIG, else PATH)")
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--stdio", action="store_true", help="be the program of `surfmap-rig --driver`")
    mode.add_argument("--server", help="run the Python rig loop against this surfmapd (host:port)")
    parser.add_argument("--job", type=int, default=0, help="with --server: only this job (default any)")
    parser.add_argument("--rig-id", default=os.uname().nodename, help="with --server: the rig's name")
    parser.add_argument("--token", default=os.environ.get("SURFMAP_TOKEN"), help="bearer token (env SURFMAP_TOKEN)")
    parser.add_argument("--spool", help="with --server: spool directory (default: the rig id's under ~/.local/state)")
    parser.add_argument("--retry-for", type=float, default=300.0, help="with --server: seconds to wait out a server")
    parser.add_argument("--max-force", type=float, default=LIMITS.max_force_n, help="force ceiling, N")
    args = parser.parse_args(argv)

    def log(line: str) -> None:  # stdout carries the protocol with --stdio: log to stderr
        print(f"arm_driver: {line}", file=sys.stderr, flush=True)

    limits = SafetyLimits(max_force_n=args.max_force)
    hardware: ArmHardware
    if args.simulate:
        from simulated_arm import SimulatedArm
        hardware = SimulatedArm(args.simulate, CALIBRATION, rig_binary=args.rig)
        name = f"arm_driver.py on SimulatedArm ({args.simulate})"
    else:
        try:
            hardware = YourArm()
        except NotImplementedError as todo:
            print(f"arm_driver: {todo}", file=sys.stderr)
            return 2
        name = "arm_driver.py on YourArm"
    driver = ArmDriver(hardware, CALIBRATION, limits, log)
    try:
        if args.stdio:
            return driver_protocol.serve(driver.measure, name)
        stop = threading.Event()

        def on_signal(signum, frame) -> None:  # first: finish the probe; second: leave now
            if stop.is_set():
                raise KeyboardInterrupt
            log("stopping after the current probe (again to stop now)")
            stop.set()

        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
        with sc.connect(args.server, timeout=30.0, token=args.token) as client:
            summary = sc.run_rig(client, driver.measure, args.rig_id, args.job, spool_dir=args.spool,
                                 retry_for_s=args.retry_for, stop=stop, on_event=log)
        print(summary.format(args.rig_id))
        if summary.error is not None:
            print(f"arm_driver: {summary.error}", file=sys.stderr)
            return 1
        return 0
    finally:
        close = getattr(hardware, "close", None)  # SimulatedArm stops its simulator
        if close is not None:
            close()


if __name__ == "__main__":
    sys.exit(main())
