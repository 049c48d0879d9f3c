"""Jobs: create/get/list, pause/resume/cancel and the wrong-state error, plans,
watching until the job ends, deadlines."""

from __future__ import annotations

import subprocess

import grpc
import pytest

import surfmap_client as sc
from surfmap_client.local_processes import rig_command

from conftest import SCENE


@pytest.fixture()
def plate(client, lab) -> sc.ObjectInfo:
    return client.upload_object(lab.mesh(), name="plate-jobs")


def test_create_applies_settings_and_server_defaults(client, plate):
    job = client.create_job(plate.object_id, "roughness", "uniform", finest_level=1, budget=5, seed=42,
                            segment_length_mm=15.0, lease_s=12.5)
    assert job.job_id > 0
    assert job.state == sc.JobState.RUNNING
    spec = job.spec
    assert spec.object_id == plate.object_id
    assert spec.property == sc.Property.ROUGHNESS
    assert spec.mode == sc.SamplingMode.UNIFORM
    assert (spec.coarsest_level, spec.finest_level, spec.budget, spec.seed) == (0, 1, 5, 42)
    assert spec.probe.segment_length_mm == pytest.approx(15.0)
    assert spec.probe.speed_mm_s == pytest.approx(10.0)       # server default
    assert spec.probe.normal_force_n == pytest.approx(5.0)    # server default
    assert spec.lease_s == pytest.approx(12.5)
    assert job.created is not None and job.updated is not None
    assert job.progress.leased == 0             # nothing leased to a rig yet
    assert [level.leased for level in job.progress.levels] == [0] * len(job.progress.levels)
    assert job.progress.issued > 0              # but the plan's first sites are queued
    assert client.get_job(job.job_id).spec == spec
    assert job.job_id in [j.job_id for j in client.list_jobs(plate.object_id)]
    assert job.job_id in [j.job_id for j in client.list_jobs()]
    client.cancel_job(job.job_id)


def test_lifecycle_and_wrong_state_errors(client, plate):
    job = client.create_job(plate.object_id, finest_level=1)
    assert client.pause_job(job.job_id).state == sc.JobState.PAUSED
    assert client.get_job(job.job_id).state == sc.JobState.PAUSED
    with pytest.raises(sc.SurfmapError) as caught:
        client.pause_job(job.job_id)
    assert caught.value.code == grpc.StatusCode.FAILED_PRECONDITION
    assert caught.value.method == "PauseJob"
    assert "paused" in caught.value.message

    assert client.resume_job(job.job_id).state == sc.JobState.RUNNING
    with pytest.raises(sc.SurfmapError) as caught:
        client.resume_job(job.job_id)
    assert caught.value.code == grpc.StatusCode.FAILED_PRECONDITION

    cancelled = client.cancel_job(job.job_id)
    assert cancelled.state == sc.JobState.CANCELLED
    assert cancelled.state.finished
    for call in (client.resume_job, client.pause_job, client.cancel_job):
        with pytest.raises(sc.SurfmapError) as caught:
            call(job.job_id)
        assert caught.value.code == grpc.StatusCode.FAILED_PRECONDITION
        assert "cancelled" in caught.value.message


def test_invalid_spec_is_rejected_with_the_field_named(client, plate):
    with pytest.raises(sc.SurfmapError) as caught:
        client.create_job(plate.object_id, threshold=-1.0)
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "threshold" in caught.value.message
    with pytest.raises(sc.SurfmapError) as caught:
        client.create_job(plate.object_id, mode="random")
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT


def test_plan_lists_the_sites(client, plate):
    job = client.create_job(plate.object_id, finest_level=1)
    plan = client.get_plan(job.job_id)
    assert plan.job_id == job.job_id
    # Adaptive mode starts with every vertex of the coarsest level (the control mesh).
    level0 = [s for s in plan.sites if s.level == 0]
    assert len(level0) == plate.control_vertex_count
    assert all(s.state in (sc.SiteState.PENDING, sc.SiteState.ISSUED) for s in level0)
    assert all(s.position.shape == (3,) for s in plan.sites)
    client.cancel_job(job.job_id)


def test_unknown_job_is_not_found_everywhere(client):
    unknown = 876543
    calls = [client.get_job, client.pause_job, client.resume_job, client.cancel_job, client.get_plan,
             client.get_map, client.list_samples, client.refit,
             lambda j: client.query_map(j, [[0.0, 0.0, 0.0]]),
             lambda j: next(client.watch_job(j, timeout=30))]
    for call in calls:
        with pytest.raises(sc.SurfmapError) as caught:
            call(unknown)
        assert caught.value.code == grpc.StatusCode.NOT_FOUND, caught.value
        assert str(unknown) in caught.value.message


def test_watch_follows_a_job_to_completion(client, plate, server, lab):
    budget = 12
    job = client.create_job(plate.object_id, finest_level=1, budget=budget, seed=3)
    updates = client.watch_job(job.job_id, include_map=True, timeout=60)  # a bug fails, never hangs
    first = next(updates)  # the current state, before any rig runs
    assert first.job.job_id == job.job_id
    assert first.job.state == sc.JobState.RUNNING
    assert first.job.progress.measured == 0
    assert first.map is not None and first.map.vertex_count > 0

    rig = subprocess.Popen(rig_command(lab.rig, server.address, SCENE, job.job_id, "watch-rig"),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        seen = [first] + list(updates)  # must end by itself when the job completes
    finally:
        output, _ = rig.communicate(timeout=120)
    assert rig.returncode == 0, output
    measured = [u.job.progress.measured for u in seen]
    assert measured == sorted(measured), "progress never goes backwards"
    last = seen[-1]
    assert last.job.state == sc.JobState.COMPLETED
    assert last.job.progress.measured == budget
    assert last.map is not None and len(last.map.samples) == budget
    assert all(u.job.state == sc.JobState.RUNNING for u in seen[:-1])
    samples = [u.latest_sample for u in seen if u.latest_sample is not None]
    assert all(s.job_id == job.job_id and s.fit is not None for s in samples)


def test_watch_ends_when_the_job_is_cancelled(client, plate):
    job = client.create_job(plate.object_id, finest_level=1)
    updates = client.watch_job(job.job_id, timeout=30)
    assert next(updates).job.state == sc.JobState.RUNNING
    client.cancel_job(job.job_id)
    rest = list(updates)
    assert rest and rest[-1].job.state == sc.JobState.CANCELLED


def test_deadline_of_a_watch_that_does_not_end(client, plate):
    job = client.create_job(plate.object_id, finest_level=1)  # no rig: it never progresses
    updates = client.watch_job(job.job_id, timeout=0.5)
    with pytest.raises(sc.SurfmapError) as caught:
        list(updates)
    assert caught.value.code == grpc.StatusCode.DEADLINE_EXCEEDED
    client.cancel_job(job.job_id)


def test_closing_a_watch_early_cancels_it(client, plate):
    job = client.create_job(plate.object_id, finest_level=1)
    updates = client.watch_job(job.job_id, timeout=30)
    next(updates)
    updates.close()  # must not hang or raise
    assert client.get_job(job.job_id).state == sc.JobState.RUNNING
    client.cancel_job(job.job_id)
