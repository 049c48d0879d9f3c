"""Import of recorded traces and provenance through a real surfmapd (issues 13, 14).

A trace the simulated rig measured for the completed job is written as a CSV
file and imported into a new job on the same object, as a drag recorded
elsewhere would be."""

from __future__ import annotations

from datetime import datetime, timezone

import grpc
import pytest

import surfmap_client as sc


LAB = sc.Provenance(operator="A. Lloyd", specimen="plate #7", probe_tip="steel ball 3 mm", sensor="Nano17",
                    notes="cleaned\nwith ethanol", extra={"humidity_pct": "41"})


def test_provenance_round_trips_on_objects_and_jobs(lab, client):
    obj = client.upload_object(lab.mesh(), name="plate-provenance", provenance=LAB)
    assert obj.provenance == LAB
    assert client.get_object(obj.object_id).provenance == LAB
    assert [o.provenance for o in client.list_objects() if o.object_id == obj.object_id] == [LAB]
    job = client.create_job(obj.object_id, budget=2, provenance={"operator": "D. Pai", "specimen": "plate #7"})
    assert job.provenance == sc.Provenance(operator="D. Pai", specimen="plate #7")
    assert client.get_job(job.job_id).provenance.operator == "D. Pai"
    with pytest.raises(sc.SurfmapError) as refused:
        client.create_job(obj.object_id, budget=2, provenance=sc.Provenance(operator="x" * 201))
    assert refused.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "provenance operator" in refused.value.message


def test_import_trace_adds_a_sample_once_with_its_provenance(client, completed_job, tmp_path):
    # A drag over one material, so the map it alone makes is its mu everywhere near it.
    measured = next(s for s in client.list_samples(completed_job.job.job_id) if len(s.fit.pieces) == 1)
    csv = tmp_path / "hand_drag.csv"
    trace = client.get_trace(measured.trace_id)
    trace.to_csv(str(csv))
    job = client.create_job(completed_job.object.object_id, sc.Property.FRICTION, sc.SamplingMode.UNIFORM,
                            coarsest_level=0, finest_level=1, budget=3)
    recorded = datetime(2026, 11, 24, 9, 30, tzinfo=timezone.utc)
    sample, already = client.import_trace(job.job_id, csv, source="bench-arm", recorded=recorded, provenance=LAB)
    assert not already
    assert sample.job_id == job.job_id and sample.rig_id == "bench-arm"
    assert sample.provenance == LAB
    assert sample.import_info is not None
    assert sample.import_info.file_name == "hand_drag.csv" and sample.import_info.source == "bench-arm"
    assert sample.import_info.recorded == recorded and len(sample.import_info.file_sha256) == 64
    # The same drag as measured: the same fit, located at the middle of its forward path (a site at an open
    # edge is dragged from the edge inwards, so not at the site itself).
    assert abs(sample.fit.friction.mu - measured.fit.friction.mu) < 0.005
    middle = trace.xyz[trace.forward].mean(axis=0)
    assert float(((sample.position - middle) ** 2).sum()) ** 0.5 < 1.0
    listed = client.list_samples(job.job_id)
    assert [s.trace_id for s in listed] == [sample.trace_id]
    assert client.get_job(job.job_id).progress.measured == 0   # an import marks no planned site measured
    value = client.query_map(job.job_id, [sample.position])
    assert abs(value.mu[0] - sample.fit.friction.mu) < 0.01

    again, already = client.import_trace(job.job_id, csv.read_bytes(), source="bench-arm")
    assert already and again.trace_id == sample.trace_id

    lifted = tmp_path / "lifted.csv"
    lines = csv.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("t,"))
    columns = lines[header].split(",")
    z = columns.index("z")
    out = lines[:header + 1]
    for line in lines[header + 1:]:
        fields = line.split(",")
        fields[z] = repr(float(fields[z]) + 15.0)   # 15 mm above the plate (z = 0), within the command checks
        out.append(",".join(fields))
    lifted.write_text("\n".join(out) + "\n")
    with pytest.raises(sc.SurfmapError) as refused:
        client.import_trace(job.job_id, lifted, source="bench-arm")
    assert refused.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "implausible trace: surface:" in refused.value.message and "lifted.csv" in refused.value.message
    kept = client.list_rejected_traces(job.job_id)
    assert [(t.rig_id, t.sample_count > 0) for t in kept] == [("bench-arm", True)]
