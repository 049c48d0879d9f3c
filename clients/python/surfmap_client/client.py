"""SurfmapClient: every call of the surfmap.v1 API, typed, with a deadline.

    client = connect("127.0.0.1:50051", timeout=10.0, token=None)
    obj = client.upload_object("clients/sim/scenes/bottle.obj")
    job = client.create_job(obj.object_id, finest_level=1, threshold=2.0)
    for update in client.watch_job(job.job_id):   # ends when the job ends
        print(update.job.progress.measured)
    surface = client.get_map(job.job_id)            # numpy arrays

Every call has a deadline: the client's ``timeout`` unless the call is given
its own. Every failure raises ``SurfmapError`` (gRPC code + server message).
"""

from __future__ import annotations

import os
from pathlib import Path
from datetime import datetime, timezone
from typing import Callable, Generator, List, Optional, Sequence, Tuple, Union

import grpc
import numpy as np

from . import conversion as conv
from . import records as r
from ._stubs import pb, pb_grpc
from .errors import SurfmapError, error_from_rpc, invalid_argument

DEFAULT_TIMEOUT_S = 30.0
# A watch lasts as long as the job: its deadline is long, but there is one.
DEFAULT_WATCH_TIMEOUT_S = 24 * 3600.0
# Maps of fine levels with their mesh are large; the server's own limit is 64 MiB.
DEFAULT_MAX_MESSAGE_BYTES = 256 * 1024 * 1024

PathOrBytes = Union[str, os.PathLike, bytes]


def connect(address: str, timeout: float = DEFAULT_TIMEOUT_S, token: Optional[str] = None,
            root_certificates: Optional[Union[bytes, str, os.PathLike]] = None, tls: bool = False,
            wait_ready: bool = True, ca_file: Optional[Union[str, os.PathLike]] = None) -> "SurfmapClient":
    """Opens a channel to surfmapd at ``address`` ("host:port").

    ``timeout``: default deadline of every call, seconds. ``token``: sent as
    ``authorization: Bearer <token>`` on every call (servers configured with
    tokens require it). ``root_certificates`` (PEM bytes or a file path)
    switches to TLS with those roots; ``ca_file`` (a PEM file path, like the
    CLI's ``--ca-file``) does the same; ``tls=True`` alone uses the system roots.
    With ``wait_ready`` the channel is connected within ``timeout`` or
    SurfmapError(UNAVAILABLE) is raised.
    """
    if timeout is None or not timeout > 0:
        raise invalid_argument("connect", f"timeout must be a positive number of seconds, got {timeout!r}")
    options = [("grpc.max_receive_message_length", DEFAULT_MAX_MESSAGE_BYTES),
               ("grpc.max_send_message_length", DEFAULT_MAX_MESSAGE_BYTES)]
    credentials = None
    if ca_file is not None:
        if root_certificates is not None:
            raise invalid_argument("connect", "give ca_file or root_certificates, not both")
        root_certificates = ca_file
    if root_certificates is not None or tls:
        roots = root_certificates
        if isinstance(roots, (str, os.PathLike)):
            try:
                roots = Path(roots).read_bytes()
            except OSError as error:
                raise invalid_argument("connect", f"cannot read root certificates '{root_certificates!s}': {error}")
        credentials = grpc.ssl_channel_credentials(root_certificates=roots)

    def make_channel(own_connection: bool = False) -> grpc.Channel:
        channel_options = options + ([("grpc.use_local_subchannel_pool", 1)] if own_connection else [])
        if credentials is not None:
            return grpc.secure_channel(address, credentials, channel_options)
        return grpc.insecure_channel(address, channel_options)

    channel = make_channel()
    client = SurfmapClient(channel, timeout=timeout, token=token, address=address,
                           channel_factory=lambda: make_channel(own_connection=True))
    if wait_ready:
        try:
            grpc.channel_ready_future(channel).result(timeout=timeout)
        except grpc.FutureTimeoutError:
            channel.close()
            raise SurfmapError(grpc.StatusCode.UNAVAILABLE,
                               f"could not connect to {address} within {timeout:g} s", "connect") from None
    return client


def _mesh_format(data: bytes, name_hint: str, explicit: Optional[str]) -> int:
    if explicit is not None:
        fmt = explicit.lower()
    elif name_hint.lower().endswith(".ply") or data[:3] == b"ply":
        fmt = "ply"
    elif name_hint.lower().endswith(".stl"):
        fmt = "stl"
    else:
        fmt = "obj"
    if fmt == "obj":
        return pb.MESH_FORMAT_OBJ
    if fmt == "ply":
        return pb.MESH_FORMAT_PLY
    if fmt == "stl":
        return pb.MESH_FORMAT_STL
    raise invalid_argument("UploadObject", f"mesh format must be 'obj', 'ply' or 'stl', got {explicit!r}")


_UNITS = {"mm": pb.LENGTH_UNIT_MM, "cm": pb.LENGTH_UNIT_CM, "m": pb.LENGTH_UNIT_M, "in": pb.LENGTH_UNIT_IN}


class SurfmapClient:
    """A connection to surfmapd. Thread-safe (gRPC channels are); a context manager."""

    def __init__(self, channel: grpc.Channel, timeout: float = DEFAULT_TIMEOUT_S, token: Optional[str] = None,
                 address: Optional[str] = None,
                 channel_factory: Optional[Callable[[], grpc.Channel]] = None) -> None:
        self._channel = channel
        self._channel_factory = channel_factory
        self.timeout = timeout          # default deadline of every call, s
        self.address: str = address or ""  # as given to connect(), for messages and helpers
        self.token = token
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()
        self._objects = pb_grpc.ObjectServiceStub(channel)
        self._jobs = pb_grpc.JobServiceStub(channel)
        self._maps = pb_grpc.MapServiceStub(channel)
        self._traces = pb_grpc.TraceServiceStub(channel)

    # ------------------------------------------------------------ plumbing

    def close(self) -> None:
        self._channel.close()

    def new_channel(self) -> grpc.Channel:
        """A new channel to the same server, with the same credentials and a
        connection of its own (the caller closes it). A rig (``surfmap_client.Rig``)
        takes a fresh one after UNAVAILABLE: gRPC's channel stays in
        TRANSIENT_FAILURE for seconds after a restarted server is back. Falls
        back to this client's channel when it was not made by ``connect``."""
        return self._channel_factory() if self._channel_factory is not None else self._channel

    @property
    def metadata(self) -> tuple:
        """The metadata every call carries (the bearer token, when set)."""
        return self._metadata

    def __enter__(self) -> "SurfmapClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _call(self, method: str, rpc, request, timeout: Optional[float]):
        deadline = self.timeout if timeout is None else timeout
        try:
            return rpc(request, timeout=deadline, metadata=self._metadata)
        except grpc.RpcError as error:
            raise error_from_rpc(error, method) from None

    # ------------------------------------------------------------ objects

    def upload_object(self, mesh: PathOrBytes, name: Optional[str] = None, format: Optional[str] = None,
                      timeout: Optional[float] = None, units: Optional[str] = None,
                      scale: Optional[float] = None,
                      provenance: Optional[Union[r.Provenance, dict]] = None,
                      facets: bool = False) -> r.ObjectInfo:
        """Uploads a mesh (OBJ, PLY or STL): a file path or the file's bytes.

        The format comes from ``format`` ("obj"/"ply"/"stl"), else the file
        suffix or a leading "ply" magic, else OBJ. ``name`` defaults to the
        file's stem ("object" for bytes). ``units`` ("mm", "cm", "m", "in") or
        ``scale`` (mm per file unit) say what the coordinates are; the server
        refuses an implausible size in stated units, repairs innocuous defects
        and stores the object in mm (README: "Bring your own mesh").
        ``provenance``: a ``Provenance`` (or a dict of its fields) kept with it.
        ``facets``: the flat triangles are the object's surface (a CAD export);
        without it a coarse mesh is a Loop control mesh, whose limit surface
        rounds edges and corners.
        """
        if isinstance(mesh, (bytes, bytearray)):
            data, hint = bytes(mesh), ""
            default_name = "object"
        else:
            path = Path(mesh)
            try:
                data = path.read_bytes()
            except OSError as error:
                raise invalid_argument("UploadObject", f"cannot read mesh file '{path}': {error}") from None
            hint, default_name = path.name, path.stem
        request = pb.UploadObjectRequest(name=name if name is not None else default_name,
                                         format=_mesh_format(data, hint, format), mesh=data,
                                         provenance=conv.provenance_to_proto(provenance))
        if scale is not None:
            request.scale = scale
        elif units is not None:
            if units not in _UNITS:
                raise invalid_argument("UploadObject", f"units must be one of {sorted(_UNITS)}, got {units!r}")
            request.units = _UNITS[units]
        if facets:
            request.surface = pb.OBJECT_SURFACE_FACETS
        return conv.object_info(self._call("UploadObject", self._objects.UploadObject, request, timeout).object)

    # ------------------------------------------------------------ frames and calibration

    def set_rig_registration(self, object_id: int, rig_name: str, rotation_wxyz, translation_mm,
                             tip_radius_mm: float = 0.0, sensor_rotation_wxyz=None,
                             timeout: Optional[float] = None) -> dict:
        """Registers rig ``rig_name`` (the rig_id it leases with) to an object:
        the object's pose in the rig's base frame, p_base = R p_object + t
        (``rotation_wxyz`` a unit quaternion, ``translation_mm``), the
        tool-tip radius in mm and the F/T sensor's orientation in the base
        frame (f_base = S f_sensor; None: aligned). Stores the next version
        and returns it as a dict (``registration_id``, ``version``, ...)."""
        w, x, y, z = (float(v) for v in rotation_wxyz)
        tx, ty, tz = (float(v) for v in translation_mm)
        reg = pb.RigRegistration(object_id=object_id, rig_name=rig_name, tip_radius_mm=float(tip_radius_mm))
        reg.object_pose.rotation.CopyFrom(pb.Quaternion(w=w, x=x, y=y, z=z))
        reg.object_pose.translation_mm.CopyFrom(pb.Vec3(x=tx, y=ty, z=tz))
        if sensor_rotation_wxyz is not None:
            sw, sx, sy, sz = (float(v) for v in sensor_rotation_wxyz)
            reg.sensor_rotation.CopyFrom(pb.Quaternion(w=sw, x=sx, y=sy, z=sz))
        response = self._call("SetRigRegistration", self._objects.SetRigRegistration,
                              pb.SetRigRegistrationRequest(registration=reg), timeout)
        return _registration_dict(response.registration)

    def get_rig_registration(self, registration_id: int = 0, object_id: int = 0, rig_name: str = "",
                             timeout: Optional[float] = None) -> dict:
        """A registration by id (any version), or the latest of (object_id, rig_name)."""
        request = pb.GetRigRegistrationRequest(registration_id=registration_id, object_id=object_id,
                                               rig_name=rig_name)
        response = self._call("GetRigRegistration", self._objects.GetRigRegistration, request, timeout)
        return _registration_dict(response.registration)

    def list_rig_registrations(self, object_id: int = 0, include_history: bool = False,
                               timeout: Optional[float] = None) -> List[dict]:
        """The latest registration per (object, rig), or every version; object_id 0: all objects."""
        request = pb.ListRigRegistrationsRequest(object_id=object_id, include_history=include_history)
        response = self._call("ListRigRegistrations", self._objects.ListRigRegistrations, request, timeout)
        return [_registration_dict(r) for r in response.registrations]

    def get_object(self, object_id: int, timeout: Optional[float] = None) -> r.ObjectInfo:
        request = pb.GetObjectRequest(object_id=object_id)
        return conv.object_info(self._call("GetObject", self._objects.GetObject, request, timeout).object)

    def list_objects(self, timeout: Optional[float] = None) -> List[r.ObjectInfo]:
        response = self._call("ListObjects", self._objects.ListObjects, pb.ListObjectsRequest(), timeout)
        return [conv.object_info(o) for o in response.objects]

    def get_mesh(self, object_id: int, level: int = 0, timeout: Optional[float] = None) -> r.Mesh:
        """Limit positions, normals and triangles of subdivision level 0..6."""
        request = pb.GetMeshRequest(object_id=object_id, level=level)
        return conv.mesh(self._call("GetMesh", self._objects.GetMesh, request, timeout))

    # ------------------------------------------------------------ jobs

    def create_job(self, object_id: int, property: Union[r.Property, str] = r.Property.FRICTION,
                   mode: Union[r.SamplingMode, str] = r.SamplingMode.BOUNDARY, *,
                   coarsest_level: Optional[int] = None, finest_level: Optional[int] = None,
                   map_level: Optional[int] = None,
                   threshold: Optional[float] = None, budget: Optional[int] = None,
                   segment_length_mm: Optional[float] = None, speed_mm_s: Optional[float] = None,
                   normal_force_n: Optional[float] = None, seed: Optional[int] = None,
                   max_retries: Optional[int] = None, lease_s: Optional[float] = None,
                   provenance: Optional[Union[r.Provenance, dict]] = None,
                   timeout: Optional[float] = None) -> r.JobInfo:
        """Creates a mapping job. Settings left None take the server's defaults
        (the boundary-seeking mode with its budget of 1.5 samples per control
        vertex; levels chosen from the mesh: the map on ~1 mm edges, the plan
        two levels coarser; threshold 1 (ADAPTIVE only: other modes refuse
        one); the paper's 20 mm drag at 10 mm/s and 5 N, seed 1, 2 retries,
        60 s lease); the returned JobInfo shows the values applied."""
        try:
            prop = conv.PROPERTY_TO_PROTO[r.Property(property)]
            sampling = conv.MODE_TO_PROTO[r.SamplingMode(mode)]
        except ValueError as error:
            raise invalid_argument("CreateJob", str(error)) from None
        spec = pb.JobSpec(object_id=object_id, property=prop, mode=sampling)
        # Zero means "server default" in the proto, so unset settings stay zero.
        for field_name, value in (("coarsest_level", coarsest_level), ("finest_level", finest_level),
                                  ("map_level", map_level),
                                  ("threshold", threshold), ("budget", budget), ("seed", seed),
                                  ("max_retries", max_retries)):
            if value is not None:
                setattr(spec, field_name, value)
        for field_name, value in (("segment_length_mm", segment_length_mm), ("speed_mm_s", speed_mm_s),
                                  ("normal_force_n", normal_force_n)):
            if value is not None:
                setattr(spec.probe, field_name, value)
        if lease_s is not None:
            spec.lease.FromNanoseconds(int(round(lease_s * 1e9)))
        request = pb.CreateJobRequest(spec=spec, provenance=conv.provenance_to_proto(provenance))
        response = self._call("CreateJob", self._jobs.CreateJob, request, timeout)
        return conv.job_info(response.job)

    def get_job(self, job_id: int, timeout: Optional[float] = None) -> r.JobInfo:
        return conv.job_info(self._call("GetJob", self._jobs.GetJob, pb.GetJobRequest(job_id=job_id), timeout).job)

    def list_jobs(self, object_id: int = 0, timeout: Optional[float] = None) -> List[r.JobInfo]:
        """All jobs, or only those of ``object_id``."""
        response = self._call("ListJobs", self._jobs.ListJobs, pb.ListJobsRequest(object_id=object_id), timeout)
        return [conv.job_info(j) for j in response.jobs]

    def pause_job(self, job_id: int, timeout: Optional[float] = None) -> r.JobInfo:
        """RUNNING -> PAUSED (FAILED_PRECONDITION from a finished job)."""
        return self._set_state("PauseJob", self._jobs.PauseJob, job_id, timeout)

    def resume_job(self, job_id: int, timeout: Optional[float] = None) -> r.JobInfo:
        """PAUSED -> RUNNING (FAILED_PRECONDITION from a finished job)."""
        return self._set_state("ResumeJob", self._jobs.ResumeJob, job_id, timeout)

    def cancel_job(self, job_id: int, timeout: Optional[float] = None) -> r.JobInfo:
        """-> CANCELLED; its traces and fits stay readable."""
        return self._set_state("CancelJob", self._jobs.CancelJob, job_id, timeout)

    def _set_state(self, method: str, rpc, job_id: int, timeout: Optional[float]) -> r.JobInfo:
        return conv.job_info(self._call(method, rpc, pb.SetJobStateRequest(job_id=job_id), timeout).job)

    def get_plan(self, job_id: int, timeout: Optional[float] = None) -> r.Plan:
        """Every site of the job's plan and its state."""
        return conv.plan(self._call("GetPlan", self._jobs.GetPlan, pb.GetPlanRequest(job_id=job_id), timeout))

    def list_job_events(self, job_id: int, after_event_id: int = 0, limit: Optional[int] = None,
                        timeout: Optional[float] = None) -> List[r.JobEvent]:
        """The job's events after ``after_event_id`` (0 = from the first), oldest
        first, at most ``limit`` (1..10000; None = the server's 1000). Pass the
        last event's ``event_id`` to read on::

            events, cursor = [], 0
            while batch := client.list_job_events(job_id, cursor):
                events += batch
                cursor = batch[-1].event_id
        """
        if after_event_id < 0:
            raise invalid_argument("ListJobEvents", f"after_event_id must be >= 0, got {after_event_id}")
        if limit is not None and not 1 <= limit <= 10000:
            raise invalid_argument("ListJobEvents", f"limit must be 1..10000 (or None), got {limit}")
        request = pb.ListJobEventsRequest(job_id=job_id, after_event_id=after_event_id, limit=limit or 0)
        response = self._call("ListJobEvents", self._jobs.ListJobEvents, request, timeout)
        return [conv.job_event(e) for e in response.events]

    def latest_job_events(self, job_id: int, before_event_id: int = 0, limit: Optional[int] = None,
                          timeout: Optional[float] = None) -> List[r.JobEvent]:
        """The job's newest events, newest first: those with an id below
        ``before_event_id`` (0 = the newest there are), at most ``limit``. Pass
        the last event's ``event_id`` to page back."""
        if before_event_id < 0:
            raise invalid_argument("ListJobEvents", f"before_event_id must be >= 0, got {before_event_id}")
        if limit is not None and not 1 <= limit <= 10000:
            raise invalid_argument("ListJobEvents", f"limit must be 1..10000 (or None), got {limit}")
        request = pb.ListJobEventsRequest(job_id=job_id, newest_first=True, before_event_id=before_event_id,
                                          limit=limit or 0)
        response = self._call("ListJobEvents", self._jobs.ListJobEvents, request, timeout)
        return [conv.job_event(e) for e in response.events]

    def watch_job(self, job_id: int, include_map: bool = False,
                  timeout: Optional[float] = DEFAULT_WATCH_TIMEOUT_S) -> Generator[r.JobUpdate, None, None]:
        """Iterates over the job's progress updates until the job ends.

        The first update is the current state; the last one is the update in
        which the job is COMPLETED or CANCELLED, after which the iterator
        stops. Intermediate updates are coalesced by the server (a slow reader
        sees fewer, never stale ones). ``include_map`` adds the finest-level
        map to every update. ``timeout`` bounds the whole watch. Closing the
        iterator early (``break``, ``close()``) cancels the call. A failure
        raises SurfmapError from the iteration.
        """
        request = pb.WatchJobRequest(job_id=job_id, include_map=include_map)
        try:
            call = self._jobs.WatchJob(request, timeout=timeout, metadata=self._metadata)
        except grpc.RpcError as error:
            raise error_from_rpc(error, "WatchJob") from None
        return self._watch_updates(call)

    @staticmethod
    def _watch_updates(call) -> Generator[r.JobUpdate, None, None]:
        try:
            for message in call:
                yield conv.job_update(message)
        except grpc.RpcError as error:
            raise error_from_rpc(error, "WatchJob") from None
        finally:
            call.cancel()  # a no-op once the stream has ended

    # ------------------------------------------------------------ samples and the map

    def get_sample(self, trace_id: int, fit_version: int = 0, include_series: bool = False,
                   timeout: Optional[float] = None) -> r.Sample:
        """The sample of a trace with its fit (``fit_version`` 0 = latest). With
        ``include_series`` the fit also carries the server's per-pair mu along
        the data window and the ACF (recomputed from the stored trace with the
        fit's own options)."""
        request = pb.GetSampleRequest(trace_id=trace_id, fit_version=fit_version, include_series=include_series)
        return conv.sample(self._call("GetSample", self._maps.GetSample, request, timeout).sample)

    def list_samples(self, job_id: int, fit_version: int = 0, timeout: Optional[float] = None) -> List[r.Sample]:
        """Every sample of a job (``fit_version`` 0 = the latest fit of each trace)."""
        request = pb.ListSamplesRequest(job_id=job_id, fit_version=fit_version)
        return [conv.sample(s) for s in self._call("ListSamples", self._maps.ListSamples, request, timeout).samples]

    def get_fits(self, trace_id: int, timeout: Optional[float] = None) -> List[r.Fit]:
        """Every fit version of one trace, oldest first (refits keep the old ones)."""
        fits: List[r.Fit] = []
        latest = self.get_sample(trace_id, 0, timeout=timeout).fit
        if latest is None:
            return fits
        for version in range(1, latest.version):
            sample = self.get_sample(trace_id, version, timeout=timeout)
            if sample.fit is not None:
                fits.append(sample.fit)
        fits.append(latest)
        return fits

    def get_map(self, job_id: int, level: int = -1, include_mesh: bool = True,
                timeout: Optional[float] = None) -> r.SurfaceMap:
        """The map at ``level`` (-1 = the job's finest) as numpy arrays, with
        the level's mesh unless ``include_mesh`` is False."""
        request = pb.GetMapRequest(job_id=job_id, level=level, include_mesh=include_mesh)
        response = self._call("GetMap", self._maps.GetMap, request, timeout)
        return conv.surface_map(response.map, response.mesh if response.HasField("mesh") else None)

    def export_map(self, job_id: int, path: str, format: Optional[str] = None, level: int = -1,
                   timeout: Optional[float] = None) -> str:
        """Writes the map as a texture model file for renderers: gltf, glb, ply
        or texture-json (default from the suffix; docs/texture-model.md).
        Returns the format written."""
        from .texture_export import write_texture_file
        request = pb.GetMapRequest(job_id=job_id, level=level, include_mesh=True)
        response = self._call("GetMap", self._maps.GetMap, request, timeout)
        return write_texture_file(response, path, format)

    def query_map(self, job_id: int, points: Union[np.ndarray, Sequence[Sequence[float]]],
                  timeout: Optional[float] = None) -> r.MapQuery:
        """The map at any 3D points (N, 3), each projected to the surface."""
        array = np.asarray(points, dtype=float)
        if array.ndim == 1 and array.size == 3:
            array = array.reshape(1, 3)
        if array.ndim != 2 or array.shape[1] != 3:
            raise invalid_argument("QueryMap", f"points must have shape (N, 3), got {array.shape}")
        if not np.all(np.isfinite(array)):
            bad = int(np.argwhere(~np.isfinite(array))[0][0])
            raise invalid_argument("QueryMap", f"points[{bad}] is not finite")
        request = pb.QueryMapRequest(job_id=job_id, points=[pb.Vec3(x=p[0], y=p[1], z=p[2]) for p in array.tolist()])
        return conv.map_query(self._call("QueryMap", self._maps.QueryMap, request, timeout))

    # ------------------------------------------------------------ traces

    def import_trace(self, job_id: int, csv: PathOrBytes, source: str = "surfmap_client", *,
                     file_name: Optional[str] = None, recorded: Optional[datetime] = None,
                     provenance: Optional[Union[r.Provenance, dict]] = None,
                     timeout: Optional[float] = None) -> Tuple[r.Sample, bool]:
        """Imports a drag recorded elsewhere (a positioned trace CSV: a path or
        the file's bytes; docs/trace-format.md) into the job's map. The server
        locates it on the object, checks it as it checks a rig's trace, fits it
        and stores it with ``source`` (who or what recorded it), the file's
        name and SHA-256, ``recorded`` and ``provenance``. Returns the sample
        and whether this file had been imported into the job before (then the
        sample is that import: nothing is stored twice). Refused drags raise
        SurfmapError(INVALID_ARGUMENT "implausible trace: <check>: ...") and
        are kept in ``list_rejected_traces``."""
        if isinstance(csv, (bytes, bytearray)):
            data, default_name = bytes(csv), ""
        else:
            path = Path(csv)
            try:
                data = path.read_bytes()
            except OSError as error:
                raise invalid_argument("ImportTrace", f"cannot read trace file '{path}': {error}") from None
            default_name = path.name
        request = pb.ImportTraceRequest(job_id=job_id, csv=data, source=source,
                                        file_name=file_name if file_name is not None else default_name,
                                        provenance=conv.provenance_to_proto(provenance))
        if recorded is not None:
            if recorded.tzinfo is None:
                raise invalid_argument("ImportTrace", "recorded must be a timezone-aware datetime")
            request.recorded.FromDatetime(recorded.astimezone(timezone.utc))
        response = self._call("ImportTrace", self._traces.ImportTrace, request, timeout)
        return conv.sample(response.sample), response.already_imported

    def list_rejected_traces(self, job_id: int, timeout: Optional[float] = None) -> List[r.RejectedTrace]:
        """Traces the job refused as implausible (rigs' and imports'), oldest first."""
        request = pb.ListRejectedTracesRequest(job_id=job_id)
        response = self._call("ListRejectedTraces", self._traces.ListRejectedTraces, request, timeout)
        return [conv.rejected_trace(t) for t in response.rejected_traces]

    def get_trace(self, trace_id: int, timeout: Optional[float] = None) -> r.Trace:
        """Every sample of a stored drag trace, bit-exact."""
        return conv.trace(self._call("GetTrace", self._traces.GetTrace, pb.GetTraceRequest(trace_id=trace_id), timeout))

    def refit(self, job_id: int, step_mm: Optional[float] = None, ar_order: Optional[int] = None,
              method: Union[r.ArMethod, str] = r.ArMethod.BURG, noise_aware: Optional[bool] = None,
              timeout: Optional[float] = None) -> r.RefitResult:
        """Refits every trace of a job with these estimator settings; a new
        fit version is stored per trace (the old ones stay). None = server
        default (0.1 mm grid step, order 2, noise-aware AR fit)."""
        try:
            ar_method = conv.AR_METHOD_TO_PROTO[r.ArMethod(method)]
        except ValueError as error:
            raise invalid_argument("RefitJob", str(error)) from None
        settings = pb.EstimatorSettings(step_mm=step_mm or 0.0, ar_order=ar_order or 0, ar_method=ar_method)
        if noise_aware is not None:
            settings.noise_aware = noise_aware
        response = self._call("RefitJob", self._traces.RefitJob, pb.RefitJobRequest(job_id=job_id, settings=settings),
                              timeout)
        return r.RefitResult(response.fit_version, response.refitted, response.failed)


def _registration_dict(m) -> dict:
    """pb.RigRegistration -> a plain dict (numbers as floats, quaternions as [w, x, y, z])."""
    q = m.object_pose.rotation
    t = m.object_pose.translation_mm
    s = m.sensor_rotation
    return {"registration_id": m.registration_id, "object_id": m.object_id, "rig_name": m.rig_name,
            "version": m.version, "rotation_wxyz": [q.w, q.x, q.y, q.z], "translation_mm": [t.x, t.y, t.z],
            "tip_radius_mm": m.tip_radius_mm, "sensor_rotation_wxyz": [s.w, s.x, s.y, s.z]}
