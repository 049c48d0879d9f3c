"""trace_analysis against closed-form answers (no server)."""

from __future__ import annotations

import numpy as np
import pytest

from surfmap_client import Phase, Trace
from surfmap_client import trace_analysis as ta


def synthetic_drag(mu: float, normal: np.ndarray, speed_jitter: float = 0.0, seed: int = 1) -> Trace:
    """Coulomb drag on a tilted plane: force = f_n n - mu f_n u (u the motion)."""
    rng = np.random.default_rng(seed)
    n = normal / np.linalg.norm(normal)
    u = np.cross(n, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    f_n = 5.0
    s_fwd = np.sort(rng.uniform(0, 20, 200)) if speed_jitter else np.linspace(0, 20, 200)
    s_rev = np.sort(rng.uniform(0, 20, 190))[::-1] if speed_jitter else np.linspace(20, 0, 190)
    s_pause = np.full(50, 20.0)
    xyz = np.concatenate([s_fwd, s_pause, s_rev])[:, None] * u[None, :]
    f_fwd = np.tile(f_n * n - mu * f_n * u, (len(s_fwd), 1))
    f_pause = np.tile(f_n * n, (len(s_pause), 1))
    f_rev = np.tile(f_n * n + mu * f_n * u, (len(s_rev), 1))
    phase = np.concatenate([np.full(len(s_fwd), Phase.FORWARD), np.full(len(s_pause), Phase.PAUSE),
                            np.full(len(s_rev), Phase.REVERSE)]).astype(np.int8)
    t = np.arange(len(phase)) * 0.01
    return Trace(1, 1, 1, t, xyz, np.concatenate([f_fwd, f_pause, f_rev]), phase)


@pytest.mark.parametrize("mu", [0.106, 0.305, 0.5])
def test_per_point_mu_and_normal_on_a_tilted_plane(mu):
    normal = np.array([np.sin(np.radians(23)), 0.0, np.cos(np.radians(23))])
    points = ta.per_point_friction(synthetic_drag(mu, normal, speed_jitter=1.0), (2.0, 18.0))
    assert len(points.s) > 100
    assert points.s.min() >= 2.0 and points.s.max() <= 18.0
    np.testing.assert_allclose(points.mu, mu, atol=1e-9)
    np.testing.assert_allclose(points.normal, np.tile(normal, (len(points.s), 1)), atol=1e-9)


def test_force_variation_of_pure_coulomb_friction_is_zero():
    normal = np.array([0.0, 0.0, 1.0])
    passes = ta.force_variation(synthetic_drag(0.3, normal), 0.3, (2.0, 18.0), step_mm=0.1)
    assert len(passes) == 2
    for grid, values in passes:
        assert len(grid) == 161  # 2.0, 2.1, ..., 18.0
        np.testing.assert_allclose(values, 0.0, atol=1e-9)


def test_projection_onto_a_polyline():
    line = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]])
    s, dist = ta.project_onto_polyline(np.array([[3.0, 1.0, 0.0], [11.0, 4.0, 0.0], [-2.0, 0.0, 0.0]]), line)
    np.testing.assert_allclose(s, [3.0, 14.0, 0.0])
    np.testing.assert_allclose(dist, [1.0, 1.0, 2.0])


def test_ar_model_autocorrelation_closed_forms():
    # AR(1): rho_k = a^k.
    np.testing.assert_allclose(ta.ar_model_autocorrelation([0.6], 5), 0.6 ** np.arange(6), atol=1e-12)
    # AR(2): rho_1 = a1 / (1 - a2), then the recursion (masonite, Lloyd & Pai).
    a1, a2 = 1.61, -0.73
    rho = ta.ar_model_autocorrelation([a1, a2], 4)
    assert rho[1] == pytest.approx(a1 / (1 - a2), abs=1e-12)
    assert rho[2] == pytest.approx(a1 * rho[1] + a2, abs=1e-12)
    assert rho[4] == pytest.approx(a1 * rho[3] + a2 * rho[2], abs=1e-12)


def test_sample_acf_of_a_synthesised_process_matches_the_model():
    coefficients = [0.60, 0.25]  # rubber
    x = ta.synthesize_ar(coefficients, sigma=0.11, n=40000, seed=2001)
    assert np.std(x) == pytest.approx(0.11 / np.sqrt(1 - 0.6 * ta.ar_model_autocorrelation(coefficients, 1)[1]
                                                       - 0.25 * ta.ar_model_autocorrelation(coefficients, 2)[2]),
                                      rel=0.05)
    measured = ta.autocorrelation([x[:20000], x[20000:]], 10)
    np.testing.assert_allclose(measured, ta.ar_model_autocorrelation(coefficients, 10), atol=0.03)
    # Seeded: the same seed gives the same series.
    np.testing.assert_array_equal(ta.synthesize_ar(coefficients, 0.11, 50, seed=5),
                                  ta.synthesize_ar(coefficients, 0.11, 50, seed=5))


def test_errors_name_the_problem():
    trace = synthetic_drag(0.2, np.array([0.0, 0.0, 1.0]))
    no_reverse = Trace(2, 1, 1, trace.t, trace.xyz, trace.f, np.full(len(trace.t), Phase.FORWARD, dtype=np.int8))
    with pytest.raises(ValueError, match="reverse"):
        ta.pass_geometry(no_reverse)
    with pytest.raises(ValueError, match="constant"):
        ta.autocorrelation([np.ones(10)], 3)
