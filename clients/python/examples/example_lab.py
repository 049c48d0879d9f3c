"""What the examples share: reach a surfmapd (the one at --server, or a fresh
local one on loopback), and measure a scene with simulated rigs.

Binaries: --surfmapd / --rig, else $SURFMAPD / $SURFMAP_RIG, else PATH.
Scenes: --scenes, else $SURFMAP_SCENES (first entry), else clients/sim/scenes of
this source tree.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
import tempfile
import threading
from pathlib import Path
from typing import Iterator, List, Optional

import surfmap_client as sc
from surfmap_client.local_processes import LocalServer, find_binary, rig_command


def add_lab_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--server", help="address of a running surfmapd (default: start one on 127.0.0.1)")
    parser.add_argument("--token", default=os.environ.get("SURFMAP_TOKEN"), help="bearer token (env SURFMAP_TOKEN)")
    parser.add_argument("--timeout", type=float, default=30.0, help="deadline of every call, s")
    parser.add_argument("--surfmapd", help="surfmapd binary, when starting one (env SURFMAPD)")
    parser.add_argument("--rig", help="surfmap-rig binary (env SURFMAP_RIG)")
    parser.add_argument("--scenes", help="directory of the scene files (env SURFMAP_SCENES)")
    parser.add_argument("--workdir", help="where the local server's database and logs go (default: a temp dir)")


def scenes_dir(args: argparse.Namespace) -> Path:
    if args.scenes:
        return Path(args.scenes)
    if os.environ.get("SURFMAP_SCENES"):
        return Path(os.environ["SURFMAP_SCENES"].split(":")[0])
    return Path(__file__).resolve().parents[2] / "scenes"


@contextlib.contextmanager
def open_lab(args: argparse.Namespace) -> Iterator[sc.SurfmapClient]:
    """A client of args.server, or of a local surfmapd started for this run (stopped at the end)."""
    if args.server:
        with sc.connect(args.server, timeout=args.timeout, token=args.token) as client:
            yield client
        return
    surfmapd = find_binary("surfmapd", "SURFMAPD", args.surfmapd)
    with contextlib.ExitStack() as stack:
        workdir = args.workdir or stack.enter_context(tempfile.TemporaryDirectory(prefix="surfmap-example-"))
        os.makedirs(workdir, exist_ok=True)
        server = stack.enter_context(LocalServer(surfmapd, os.path.join(workdir, "surfmap.db"),
                                                 os.path.join(workdir, "surfmapd.log")))
        print(f"started surfmapd on {server.address} (database {workdir}/surfmap.db)", file=sys.stderr)
        client = stack.enter_context(sc.connect(server.address, timeout=args.timeout, token=args.token))
        yield client


def measure(client: sc.SurfmapClient, args: argparse.Namespace, scene: str, job_id: int, rigs: int = 2,
            progress: bool = True) -> sc.JobInfo:
    """Runs `rigs` simulated rigs on the job and follows it with WatchJob until it ends.

    A rig that fails cancels the job (so the watch ends) and raises RuntimeError with its output."""
    rig = find_binary("surfmap-rig", "SURFMAP_RIG", args.rig)
    env = dict(os.environ)
    env.setdefault("SURFMAP_SCENES", str(scenes_dir(args)))
    processes = [subprocess.Popen(rig_command(rig, client.address, scene, job_id, f"example-rig-{i + 1}",
                                              args.token),
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
                 for i in range(rigs)]
    failures: List[str] = []

    def wait_for_rigs() -> None:
        for process in processes:
            output, _ = process.communicate()
            if process.returncode != 0:
                failures.append(f"surfmap-rig exited with code {process.returncode}:\n{output}")
        if failures:
            with contextlib.suppress(sc.SurfmapError):
                client.cancel_job(job_id)  # ends the watch below

    waiter = threading.Thread(target=wait_for_rigs, daemon=True)
    waiter.start()
    last: Optional[sc.JobUpdate] = None
    try:
        for last in client.watch_job(job_id):
            if progress and sys.stderr.isatty():
                p = last.job.progress
                print(f"\r  job {job_id}: {p.measured} measured, {p.issued} issued, {p.pending} pending ",
                      end="", file=sys.stderr, flush=True)
        if progress and last is not None:
            p = last.job.progress
            print(f"\r  job {job_id}: {last.job.state.name.lower()}, {p.measured} measured, {p.failed} failed, "
                  f"{p.skipped} skipped", file=sys.stderr)
    finally:
        for process in processes:
            if process.poll() is None and (last is None or not last.job.state.finished):
                process.terminate()
        waiter.join()
    if failures:
        raise RuntimeError("\n".join(failures))
    assert last is not None
    return last.job
