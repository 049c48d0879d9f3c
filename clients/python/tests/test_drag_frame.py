"""drag_frame on drags made here with known physics (no server): Coulomb
friction mu at 5 N, dragged along x, along y, down a wall and around a
cylinder; the same cases as the dashboard's lib/drag_frame_test.js."""

from __future__ import annotations

from typing import Callable

import numpy as np
import pytest

from surfmap_client import Phase, Trace
from surfmap_client.drag_frame import drag_frame_forces

NORMAL_N = 5.0
Curve = Callable[[float], np.ndarray]


def drag(path: Curve, normal_at: Curve, mu: float, count: int = 200) -> Trace:
    rows = []

    def push(u: float, direction: int, phase: Phase) -> None:
        h = 1e-4
        d = path(min(1.0, u + h)) - path(max(0.0, u - h))
        m = direction * d / np.linalg.norm(d)
        force = NORMAL_N * normal_at(u) - mu * NORMAL_N * m
        rows.append((path(u), force, phase))

    for k in range(count):
        push(k / (count - 1), 1, Phase.FORWARD)
    for _ in range(10):
        push(1.0, 1, Phase.PAUSE)
    for k in range(count):
        push(max(0.0, 1 - (k + 0.5) / (count - 1)), -1, Phase.REVERSE)
    xyz = np.array([r[0] for r in rows])
    f = np.array([r[1] for r in rows])
    phase = np.array([r[2] for r in rows], dtype=np.int8)
    return Trace(1, 1, 1, np.arange(len(rows)) * 0.01, xyz, f, phase)


def check(trace: Trace, mu: float) -> None:
    framed = drag_frame_forces(trace)
    assert framed.normal_source == "pairs"
    moving = ~trace.pause
    sign = np.where(trace.forward, -1.0, 1.0)[moving]
    np.testing.assert_allclose(framed.normal[moving], NORMAL_N, atol=0.02)
    np.testing.assert_allclose(framed.along[moving], sign * mu * NORMAL_N, atol=0.02)
    np.testing.assert_allclose(framed.lateral[moving], 0.0, atol=0.02)
    assert np.all(np.isnan(framed.along[trace.pause]))
    assert framed.window_friction(trace, 2.0, framed.path_length_mm - 2.0) == pytest.approx(mu, abs=0.002)


def test_along_x_and_along_y_read_the_same():
    flat = lambda u: np.array([0.0, 0.0, 1.0])  # noqa: E731
    check(drag(lambda u: np.array([20 * u, 0.0, 0.0]), flat, 0.3), 0.3)
    along_y = drag(lambda u: np.array([0.0, 20 * u, 0.0]), flat, 0.13)
    check(along_y, 0.13)
    assert np.all(np.abs(along_y.f[:, 0]) < 1e-12), "world fx shows no friction on this drag"


def test_a_vertical_drag_and_a_cylinder():
    check(drag(lambda u: np.array([0.0, 0.0, 30 - 20 * u]), lambda u: np.array([1.0, 0.0, 0.0]), 0.5), 0.5)
    r, arc = 40.0, 20.0 / 40.0
    angle = lambda u: -arc / 2 + arc * u  # noqa: E731
    check(drag(lambda u: np.array([r * np.cos(angle(u)), 5.0, r * np.sin(angle(u))]),
               lambda u: np.array([np.cos(angle(u)), 0.0, np.sin(angle(u))]), 0.25), 0.25)


def test_the_fit_normal_without_pairs_and_errors_named():
    trace = drag(lambda u: np.array([0.0, 20 * u, 0.0]), lambda u: np.array([0.0, 0.0, 1.0]), 0.2, count=20)
    trace.f[trace.reverse] = 0.0
    with pytest.raises(ValueError, match="no pair normal and no fit normal"):
        drag_frame_forces(trace)
    framed = drag_frame_forces(trace, fallback_normal=[0.0, 0.1, 1.0])
    assert framed.normal_source == "fit"
    assert framed.along[5] == pytest.approx(-0.2 * NORMAL_N)
    one_pass = Trace(1, 1, 1, trace.t, trace.xyz, trace.f, np.full(len(trace.t), Phase.FORWARD, dtype=np.int8))
    with pytest.raises(ValueError, match=r"has 50 and 0"):
        drag_frame_forces(one_pass)
    still = Trace(1, 1, 1, trace.t, np.zeros_like(trace.xyz), trace.f, trace.phase)
    with pytest.raises(ValueError, match="does not move"):
        drag_frame_forces(still)
