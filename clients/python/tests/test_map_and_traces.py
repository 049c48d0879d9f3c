"""The map, samples, fits, traces and refits of a completed job."""

from __future__ import annotations

import json

import grpc
import numpy as np
import pytest

import surfmap_client as sc
from surfmap_client.local_processes import score_map

from conftest import JOB_BUDGET, SCENE


def test_map_arrays_have_the_right_shapes_and_finite_values(client, completed_job):
    job = completed_job.job
    surface = client.get_map(job.job_id)
    assert surface.job_id == job.job_id
    assert surface.level == job.spec.map_level >= job.spec.finest_level
    n = surface.vertex_count
    mesh = client.get_mesh(completed_job.object.object_id, surface.level)
    assert n == len(mesh.positions)
    for name in ("mu", "mu_uncertainty", "sigma", "a1", "a2"):
        values = getattr(surface, name)
        assert values.shape == (n,), name
        assert np.all(np.isfinite(values)), name
    assert surface.positions.shape == (n, 3) and surface.normals.shape == (n, 3)
    np.testing.assert_allclose(surface.positions, mesh.positions, atol=1e-9)
    assert surface.triangles.shape == mesh.triangles.shape
    assert np.all(surface.mu_uncertainty >= 0)
    # The plate's materials have mu 0.25 .. 0.42 (clients/sim/scenes/plate.json).
    assert 0.2 < surface.mu.min() <= surface.mu.max() < 0.5

    s = len(surface.samples)
    assert s == JOB_BUDGET == job.progress.measured
    assert surface.sample_positions.shape == (s, 3)
    assert surface.sample_drag_directions.shape == (s, 3)
    assert surface.sample_sites.shape == (s, 2)
    assert surface.sample_mu.shape == (s,)
    assert np.all(np.isfinite(surface.sample_mu))
    np.testing.assert_allclose(np.linalg.norm(surface.sample_drag_directions, axis=1), 1.0, atol=1e-6)


def test_coarser_level_and_map_without_mesh(client, completed_job):
    job = completed_job.job
    level0 = client.get_map(job.job_id, level=0, include_mesh=False)
    assert level0.level == 0
    assert level0.vertex_count == completed_job.object.control_vertex_count
    assert level0.positions is None and level0.triangles is None
    assert level0.mu.shape == (level0.vertex_count,)


def test_query_at_the_samples_returns_their_measurement(client, completed_job):
    surface = client.get_map(completed_job.job.job_id)
    query = client.query_map(completed_job.job.job_id, surface.sample_positions)
    assert query.mu.shape == (len(surface.samples),)
    assert query.surface_points.shape == (len(surface.samples), 3)
    np.testing.assert_allclose(query.distance_mm, 0.0, atol=1e-6)
    # The map takes each region's pooled mu; a site's drag may straddle a
    # boundary (its mean is a blend), so compare the typical site: the
    # plate's closest materials differ by 0.05, a region's pooled mu is
    # within its drags' repeatability (~0.01) of each pure drag.
    assert np.median(np.abs(query.mu - surface.sample_mu)) < 0.02
    # A query at a vertex answers the vertex's own map value and region.
    at_vertices = client.query_map(completed_job.job.job_id, surface.positions[:50])
    np.testing.assert_allclose(at_vertices.mu, surface.mu[:50], atol=1e-9)
    np.testing.assert_array_equal(at_vertices.region, surface.region[:50])
    assert len(surface.regions) >= 1 and surface.region.max() < len(surface.regions)
    # Each region names the drag pieces behind it, by the samples' trace ids;
    # a material's weights make its mu.
    traces = {s.trace_id for s in surface.samples}
    by_material: dict[int, list[float]] = {}
    for region in surface.regions:
        assert len(region.pieces) == region.piece_count
        for piece in region.pieces:
            assert piece.trace_id in traces and piece.fit_piece >= 0
            weights = by_material.setdefault(region.material, [0.0, 0.0])
            weights[0] += piece.mu_weight
            weights[1] += piece.mu_weight * piece.mu
    for region in surface.regions:
        assert by_material[region.material][0] == pytest.approx(1.0, abs=1e-9)
        assert by_material[region.material][1] == pytest.approx(region.mu, abs=1e-9)
    # A point 5 mm above the (z = 0) plate projects onto it.
    above = client.query_map(completed_job.job.job_id, [0.0, 0.0, 5.0])
    assert above.distance_mm[0] == pytest.approx(5.0, abs=1e-6)
    assert above.surface_points[0, 2] == pytest.approx(0.0, abs=1e-9)


def test_query_points_are_checked_before_sending(client, completed_job):
    for bad in ([[1.0, 2.0]], [[0.0, float("nan"), 0.0]]):
        with pytest.raises(sc.SurfmapError) as caught:
            client.query_map(completed_job.job.job_id, bad)
        assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT


def test_samples_and_their_fits(client, completed_job):
    samples = client.list_samples(completed_job.job.job_id)
    assert len(samples) == JOB_BUDGET
    first = samples[0]
    again = client.get_sample(first.trace_id)
    assert again.trace_id == first.trace_id
    assert again.fit.friction.mu == first.fit.friction.mu
    fit = first.fit
    assert fit.version >= 1
    assert 0.0 < fit.friction.window_start_mm < fit.friction.window_end_mm <= first.segment_length_mm
    assert fit.friction.pair_count > 10
    assert len(fit.roughness.ar_coefficients) == 2  # the job maps BOTH: AR(2) by default
    assert fit.roughness.a1 == fit.roughness.ar_coefficients[0]
    assert fit.noise_std > 0
    # Every drag comes back as pieces tiling its data window, one more than
    # the changes found inside it.
    for s in samples:
        pieces = s.fit.pieces
        assert len(pieces) == len(s.fit.change_s_mm) + 1
        assert pieces[0].start_mm == pytest.approx(s.fit.friction.window_start_mm)
        assert pieces[-1].end_mm == pytest.approx(s.fit.friction.window_end_mm)
        for p in pieces:
            assert p.roughness_state in ("fitted", "too_short", "fit_failed")
            assert (p.roughness is not None) == (p.roughness_state == "fitted")


def test_sample_series_from_the_server(client, completed_job):
    sample = client.list_samples(completed_job.job.job_id)[0]
    assert sample.fit.friction.pair_mu.size == 0 and sample.fit.roughness.acf.size == 0  # lists: summary only
    detailed = client.get_sample(sample.trace_id, include_series=True)
    friction = detailed.fit.friction
    assert friction.pair_mu.shape == (friction.pair_count,) == friction.pair_s_mm.shape
    assert friction.pair_mu.mean() == pytest.approx(friction.mu, abs=1e-12)
    assert np.all(np.diff(friction.pair_s_mm) >= 0)
    assert friction.window_start_mm - 1e-9 <= friction.pair_s_mm[0]
    assert friction.pair_s_mm[-1] <= friction.window_end_mm + 1e-9
    roughness = detailed.fit.roughness
    assert roughness.acf[0] == pytest.approx(1.0) and roughness.acf.size > 10
    assert roughness.grid_step_mm == pytest.approx(0.1)


def test_trace_arrays(client, completed_job):
    sample = client.list_samples(completed_job.job.job_id)[0]
    trace = client.get_trace(sample.trace_id)
    n = len(trace.t)
    assert n > 100
    assert trace.trace_id == sample.trace_id and trace.job_id == completed_job.job.job_id
    assert trace.xyz.shape == (n, 3) and trace.f.shape == (n, 3) and trace.phase.shape == (n,)
    assert np.all(np.isfinite(trace.xyz)) and np.all(np.isfinite(trace.f))
    assert np.all(np.diff(trace.t) > 0)
    # Phases in order: forward, then pause, then reverse.
    assert set(np.unique(trace.phase)) == {sc.Phase.FORWARD, sc.Phase.PAUSE, sc.Phase.REVERSE}
    assert np.all(np.diff(trace.phase) >= 0)
    assert trace.forward.sum() > 50 and trace.reverse.sum() > 50
    # The forward drag is about segment_length_mm long, along the commanded direction.
    forward = trace.xyz[trace.forward]
    travel = forward[-1] - forward[0]
    assert np.linalg.norm(travel) == pytest.approx(sample.segment_length_mm, rel=0.15)
    assert np.dot(travel / np.linalg.norm(travel), sample.drag_direction) > 0.95


def test_trace_csv_round_trips_exactly(client, completed_job, tmp_path):
    sample = client.list_samples(completed_job.job.job_id)[1]
    trace = client.get_trace(sample.trace_id)
    path = tmp_path / "trace.csv"
    trace.to_csv(str(path))
    rows = [line.split(",") for line in path.read_text().splitlines() if not line.startswith("#")]
    assert rows[0] == ["t", "x", "y", "z", "fx", "fy", "fz", "phase"]
    values = np.array([[float(v) for v in row[:7]] for row in rows[1:]])
    np.testing.assert_array_equal(values[:, 0], trace.t)
    np.testing.assert_array_equal(values[:, 4:7], trace.f)
    assert {row[7] for row in rows[1:]} == {"fwd", "pause", "rev"}


def test_refit_creates_a_new_fit_version_and_keeps_the_old(client, completed_job):
    job_id = completed_job.job.job_id
    before = client.list_samples(job_id)
    result = client.refit(job_id, method=sc.ArMethod.LEAST_SQUARES, ar_order=3)
    assert result.refitted == len(before)
    assert result.failed == 0
    assert result.fit_version == max(s.fit.version for s in before) + 1
    after = client.list_samples(job_id)
    assert {s.fit.version for s in after} == {result.fit_version}
    assert all(len(s.fit.roughness.ar_coefficients) == 3 for s in after)
    trace_id = before[0].trace_id
    old = client.get_sample(trace_id, fit_version=before[0].fit.version)
    assert old.fit.version == before[0].fit.version
    assert old.fit.fit_id == before[0].fit.fit_id
    assert len(old.fit.roughness.ar_coefficients) == 2
    versions = [f.version for f in client.get_fits(trace_id)]
    assert versions == list(range(1, result.fit_version + 1))
    with pytest.raises(sc.SurfmapError) as caught:
        client.get_sample(trace_id, fit_version=result.fit_version + 5)
    assert caught.value.code == grpc.StatusCode.NOT_FOUND


def test_unknown_trace_is_not_found(client):
    for call in (client.get_trace, client.get_sample, client.get_fits):
        with pytest.raises(sc.SurfmapError) as caught:
            call(765432)
        assert caught.value.code == grpc.StatusCode.NOT_FOUND


def test_map_file_is_read_by_surfmap_rig_score(client, completed_job, lab, tmp_path):
    surface = client.get_map(completed_job.job.job_id)
    path = tmp_path / "map.json"
    sc.write_map_file(surface, str(path))
    document = json.loads(path.read_text())
    assert document["format"] == "surfmap.map.v1"
    assert len(document["vertices"]["mu"]) == surface.vertex_count
    score = score_map(lab.rig, SCENE, str(path))
    assert score["vertices"] == surface.vertex_count
    assert score["samples"] == len(surface.samples)
    assert 0.0 <= score["mu_rmse"] < 0.2
    with pytest.raises(ValueError):
        sc.map_to_document(client.get_map(completed_job.job.job_id, include_mesh=False))


def test_python_recomputation_agrees_with_the_server_fit(client, completed_job):
    """trace_analysis (used by plot_trace) against the server's estimator on real traces."""
    from surfmap_client import trace_analysis as ta

    for sample in client.list_samples(completed_job.job.job_id):
        friction = sample.fit.friction
        points = ta.per_point_friction(client.get_trace(sample.trace_id),
                                       (friction.window_start_mm, friction.window_end_mm))
        assert abs(len(points.s) - friction.pair_count) <= 3, sample.trace_id
        assert points.mu.mean() == pytest.approx(friction.mu, abs=0.01), sample.trace_id
        # The server smooths the forward path lightly before pairing, this does not: the spread
        # of the per-point mu on rough drags differs by up to ~15% (measured on the plate).
        assert points.mu.std() == pytest.approx(friction.mu_std, rel=0.25, abs=0.005), sample.trace_id
