"""The read side of a job's history: ListJobEvents (with its cursor) and the
rig of each sample, against the real surfmapd and the completed plate job
measured by one simulated rig (``py-rig-1``, see conftest)."""

from __future__ import annotations

import grpc
import pytest

import surfmap_client as sc

RIG = "py-rig-1"


def all_events(client: sc.SurfmapClient, job_id: int, page: int) -> list:
    events, cursor = [], 0
    while batch := client.list_job_events(job_id, cursor, limit=page):
        assert len(batch) <= page
        events += batch
        cursor = batch[-1].event_id
    return events


def test_events_tell_the_jobs_story(client, completed_job):
    job = completed_job.job
    events = client.list_job_events(job.job_id)
    assert events[0].kind == "job_created"
    assert events[0].detail["initial_commands"] > 0
    ids = [e.event_id for e in events]
    assert ids == sorted(ids) and len(set(ids)) == len(ids), "event ids increase"
    assert all(e.job_id == job.job_id and e.time is not None and e.detail_error == "" for e in events)
    accepted = [e for e in events if e.kind == "trace_accepted"]
    assert len(accepted) == job.progress.measured
    assert {e.detail["rig"] for e in accepted} == {RIG}
    samples = {s.command_id: s for s in client.list_samples(job.job_id)}
    for e in accepted:
        sample = samples[e.detail["command_id"]]
        assert (e.detail["level"], e.detail["vertex"]) == (sample.level, sample.vertex)
        assert e.detail["mu"] == pytest.approx(sample.fit.friction.mu, abs=1e-12)


def test_the_cursor_and_the_limit_page_through_the_same_events(client, completed_job):
    job_id = completed_job.job.job_id
    whole = client.list_job_events(job_id, limit=10000)
    assert [e.event_id for e in all_events(client, job_id, page=7)] == [e.event_id for e in whole]
    middle = whole[len(whole) // 2].event_id
    rest = [e.event_id for e in whole if e.event_id > middle]
    assert [e.event_id for e in client.list_job_events(job_id, middle)] == rest
    assert client.list_job_events(job_id, whole[-1].event_id) == []


def test_newest_first_pages_back_through_the_same_events(client, completed_job):
    job_id = completed_job.job.job_id
    whole = [e.event_id for e in client.list_job_events(job_id, limit=10000)]
    back, cursor = [], 0
    while batch := client.latest_job_events(job_id, cursor, limit=5):
        assert len(batch) <= 5
        back += [e.event_id for e in batch]
        cursor = batch[-1].event_id
    assert back == whole[::-1]
    assert [e.event_id for e in client.latest_job_events(job_id, limit=1)] == [whole[-1]]


def test_every_sample_names_its_rig(client, completed_job):
    samples = client.list_samples(completed_job.job.job_id)
    assert samples and {s.rig_id for s in samples} == {RIG}
    one = client.get_sample(samples[0].trace_id)
    assert one.rig_id == RIG


def test_bad_event_requests_are_refused_with_the_reason(client, completed_job):
    job_id = completed_job.job.job_id
    for kwargs, text in (({"after_event_id": -1}, "after_event_id must be >= 0"),
                         ({"limit": 0}, "limit must be 1..10000"),
                         ({"limit": 10001}, "limit must be 1..10000")):
        with pytest.raises(sc.SurfmapError) as caught:
            client.list_job_events(job_id, **kwargs)
        assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
        assert text in caught.value.message
    with pytest.raises(sc.SurfmapError) as caught:
        client.list_job_events(987654)
    assert caught.value.code == grpc.StatusCode.NOT_FOUND
    assert caught.value.method == "ListJobEvents"
