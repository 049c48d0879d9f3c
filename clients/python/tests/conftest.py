"""Fixtures: a REAL surfmapd on 127.0.0.1 (free port, temp SQLite file) and a
small completed job measured by a real ``surfmap-rig --sim plate``.

The binaries come from the environment CTest sets (SURFMAPD, SURFMAP_RIG,
SURFMAP_SCENES; see CMakeLists.txt). A missing binary or scene FAILS the
tests: nothing is skipped.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pytest

import surfmap_client as sc
from surfmap_client.local_processes import LocalServer, run_simulated_rigs

# The plate: 160 faces, flat; levels 0..1 with a small budget keep a job to well under a second.
SCENE = "plate"
JOB_BUDGET = 24
JOB_SEED = 7


@dataclass(frozen=True)
class LabPaths:
    surfmapd: str
    rig: str
    scenes: Path

    def mesh(self, scene: str = SCENE) -> Path:
        return self.scenes / f"{scene}.obj"


def _required_executable(env_var: str) -> str:
    path = os.environ.get(env_var)
    if not path:
        pytest.fail(f"{env_var} is not set: it must name the binary to test against (CTest sets it)", pytrace=False)
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        pytest.fail(f"{env_var}={path} is not an executable file: build it first", pytrace=False)
    return path


@pytest.fixture(scope="session")
def lab() -> LabPaths:
    scenes = os.environ.get("SURFMAP_SCENES")
    if not scenes or not (Path(scenes) / f"{SCENE}.obj").is_file():
        pytest.fail(f"SURFMAP_SCENES={scenes!r} must be the scenes directory holding {SCENE}.obj", pytrace=False)
    return LabPaths(_required_executable("SURFMAPD"), _required_executable("SURFMAP_RIG"), Path(scenes))


@pytest.fixture(scope="session")
def server(lab: LabPaths, tmp_path_factory):
    directory = tmp_path_factory.mktemp("surfmapd")
    with LocalServer(lab.surfmapd, str(directory / "surfmap.db"), str(directory / "surfmapd.log")) as running:
        yield running


@pytest.fixture(scope="session")
def client(server: LocalServer):
    with sc.connect(server.address, timeout=20.0) as connected:
        yield connected


@dataclass(frozen=True)
class CompletedJob:
    object: sc.ObjectInfo
    job: sc.JobInfo            # as it was when completed


@pytest.fixture(scope="session")
def completed_job(lab: LabPaths, server: LocalServer, client: sc.SurfmapClient) -> CompletedJob:
    obj = client.upload_object(lab.mesh(), name="plate-completed")
    job = client.create_job(obj.object_id, sc.Property.BOTH, sc.SamplingMode.ADAPTIVE, coarsest_level=0,
                            finest_level=1, threshold=2.0, budget=JOB_BUDGET, seed=JOB_SEED)
    run_simulated_rigs(lab.rig, server.address, SCENE, job.job_id, count=1, timeout_s=120)
    done = client.get_job(job.job_id)
    assert done.state == sc.JobState.COMPLETED, done
    return CompletedJob(obj, done)
