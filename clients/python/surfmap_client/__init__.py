"""surfmap_client: a typed Python client of surfmapd (the surfmap.v1 gRPC API).

    import surfmap_client as sc
    with sc.connect("127.0.0.1:50051", timeout=10.0) as client:
        job = client.get_job(3)
        surface = client.get_map(3)          # numpy arrays per vertex
        trace = client.get_trace(surface.samples[0].trace_id)

A rig in Python (lease, measure with your code, submit; spooled and retried
like surfmap-rig): ``sc.run_rig(client, measure, rig_id="arm-1")`` (rig.py).

Needs the stubs generated from proto/ at build time (found in the source
tree's build/ or $SURFMAP_PYTHON_STUBS; see README.md). Every failed call
raises SurfmapError.
"""

from .client import DEFAULT_TIMEOUT_S, DEFAULT_WATCH_TIMEOUT_S, SurfmapClient, connect
from .errors import SurfmapError
from .map_file import map_to_document, write_map_file
from .probe import FailureKind, Lease, ProbeCommand, RigFrameCommand, SubmitResult, check_trace, measured_trace
from .records import (ArMethod, Fit, FrictionEstimate, ImportInfo, JobEvent, JobInfo, JobProgress, JobSpec, JobState,
                      JobUpdate, LevelProgress, MapQuery, MapRegion, MapRegionPiece, Mesh, ObjectInfo, Phase, Plan,
                      PlanSite, ProbeParameters, Property, Provenance, RefitResult, RejectedTrace, RoughnessEstimate,
                      Sample, SamplingMode, SiteState, SurfaceMap, Trace)
from .rig import Rig, RigFailure, RigSummary, TracePending, TraceRejected, run_rig
from .spool import TraceSpool, default_spool_dir

__all__ = [
    "connect", "SurfmapClient", "SurfmapError", "DEFAULT_TIMEOUT_S", "DEFAULT_WATCH_TIMEOUT_S",
    "map_to_document", "write_map_file",
    "ArMethod", "Fit", "FrictionEstimate", "JobEvent", "JobInfo", "JobProgress", "JobSpec", "JobState", "JobUpdate",
    "LevelProgress", "MapQuery", "MapRegion", "MapRegionPiece", "Mesh", "ObjectInfo", "Phase", "Plan", "PlanSite",
    "ProbeParameters",
    "Property", "RefitResult", "RoughnessEstimate", "Sample", "SamplingMode", "SiteState", "SurfaceMap", "Trace",
    # import and provenance (issues 13, 14)
    "ImportInfo", "Provenance", "RejectedTrace",
    # rigs: lease, measure, submit (rig.py, probe.py, spool.py; driver_protocol.py for surfmap-rig --driver)
    "Rig", "run_rig", "RigFailure", "RigSummary", "TraceRejected", "TracePending", "FailureKind", "Lease",
    "ProbeCommand", "RigFrameCommand", "SubmitResult", "check_trace", "measured_trace", "TraceSpool",
    "default_spool_dir",
]
