"""Token auth: a surfmapd started with a config that sets tokens (format of
deploy/surfmapd.example.json) wants `authorization: Bearer <token>` and
enforces the roles read < probe < steer."""

from __future__ import annotations

import json

import grpc
import pytest

import surfmap_client as sc
from surfmap_client.local_processes import LocalServer

READ = "py-test-read-token-000001"
PROBE = "py-test-probe-token-00001"
STEER = "py-test-steer-token-00001"


@pytest.fixture(scope="module")
def guarded_server(lab, tmp_path_factory):
    directory = tmp_path_factory.mktemp("surfmapd-tokens")
    config = directory / "surfmapd.json"
    config.write_text(json.dumps({"tokens": {READ: "read", PROBE: "probe", STEER: "steer"}}))
    with LocalServer(lab.surfmapd, str(directory / "surfmap.db"), str(directory / "surfmapd.log"),
                     config_path=str(config)) as running:
        yield running


def test_without_a_token_every_call_is_unauthenticated(guarded_server):
    with sc.connect(guarded_server.address, timeout=10.0) as anonymous:
        with pytest.raises(sc.SurfmapError) as caught:
            anonymous.list_objects()
        assert caught.value.code == grpc.StatusCode.UNAUTHENTICATED
    with sc.connect(guarded_server.address, timeout=10.0, token="not-a-configured-token") as stranger:
        with pytest.raises(sc.SurfmapError) as caught:
            stranger.list_jobs()
        assert caught.value.code == grpc.StatusCode.UNAUTHENTICATED


def test_roles_are_enforced(guarded_server, lab):
    with sc.connect(guarded_server.address, timeout=10.0, token=STEER) as steer, \
            sc.connect(guarded_server.address, timeout=10.0, token=READ) as reader:
        obj = steer.upload_object(lab.mesh(), name="guarded")
        assert [o.object_id for o in reader.list_objects()] == [obj.object_id]
        with pytest.raises(sc.SurfmapError) as caught:
            reader.upload_object(lab.mesh())
        assert caught.value.code == grpc.StatusCode.PERMISSION_DENIED
        job = steer.create_job(obj.object_id, finest_level=1)
        assert reader.get_job(job.job_id).state == sc.JobState.RUNNING
        for call in (reader.pause_job, reader.cancel_job):
            with pytest.raises(sc.SurfmapError) as caught:
                call(job.job_id)
            assert caught.value.code == grpc.StatusCode.PERMISSION_DENIED
        # The watch is a read call; its stream carries the token too.
        updates = reader.watch_job(job.job_id, timeout=30)
        assert next(updates).job.job_id == job.job_id
        updates.close()
        assert steer.cancel_job(job.job_id).state == sc.JobState.CANCELLED
