"""The drag frame on real traces: every drag of the completed plate job (the
simulated rig drags in all directions of the plane) shows, in the fit's
window, the friction the server's estimator found."""

from __future__ import annotations

import pytest

from surfmap_client.drag_frame import drag_frame_forces


def test_the_drag_frame_shows_the_servers_mu_on_every_drag(client, completed_job):
    samples = client.list_samples(completed_job.job.job_id)
    assert len(samples) >= 10
    for sample in samples:
        fit = sample.fit
        assert fit is not None
        trace = client.get_trace(sample.trace_id)
        framed = drag_frame_forces(trace, fit.friction.normal)
        assert framed.normal_source == "pairs"
        seen = framed.window_friction(trace, fit.friction.window_start_mm, fit.friction.window_end_mm)
        assert seen == pytest.approx(fit.friction.mu, rel=0.1, abs=0.005), (
            f"trace {sample.trace_id} dragged along {sample.drag_direction}")
