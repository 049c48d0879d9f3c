"""Smoke tests of the examples, run as a user would (separate processes)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import numpy as np

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run_example(script: str, *args: str, timeout: float = 180.0) -> subprocess.CompletedProcess:
    result = subprocess.run([sys.executable, str(EXAMPLES / script), *args], capture_output=True, text=True,
                            timeout=timeout, env=dict(os.environ, MPLBACKEND="Agg"))
    assert result.returncode == 0, f"{script} exited {result.returncode}:\n{result.stdout}\n{result.stderr}"
    return result


def test_plot_trace_writes_a_non_trivial_png(server, completed_job, tmp_path):
    output = tmp_path / "trace.png"
    result = run_example("plot_trace.py", "--server", server.address, "--job", str(completed_job.job.job_id),
                         "-o", str(output))
    assert f"wrote {output}" in result.stdout
    data = output.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 50_000
    image = matplotlib.image.imread(str(output))
    assert image.shape[0] >= 1000 and image.shape[1] >= 1000
    assert np.std(image[..., :3]) > 0.05  # not a blank canvas


def test_plot_trace_with_a_trace_id_and_a_bad_one(server, client, completed_job, tmp_path):
    trace_id = client.list_samples(completed_job.job.job_id)[0].trace_id
    output = tmp_path / "one.png"
    run_example("plot_trace.py", "--server", server.address, "--trace", str(trace_id), "-o", str(output))
    assert output.stat().st_size > 50_000
    bad = subprocess.run([sys.executable, str(EXAMPLES / "plot_trace.py"), "--server", server.address,
                          "--trace", "999999", "-o", str(tmp_path / "bad.png")], capture_output=True, text=True,
                         timeout=60)
    assert bad.returncode == 1
    assert "NOT_FOUND" in bad.stderr
    assert not (tmp_path / "bad.png").exists()


def test_threshold_experiment_starts_its_own_lab(lab, tmp_path):
    result = run_example("threshold_experiment.py", "--scene", "plate", "--finest", "1", "--thresholds", "1", "8",
                         "--rigs", "1", "--surfmapd", lab.surfmapd, "--rig", lab.rig, "--scenes", str(lab.scenes),
                         "--workdir", str(tmp_path / "lab"))
    lines = result.stdout.splitlines()
    header = next(i for i, line in enumerate(lines) if line.lstrip().startswith("threshold"))
    rows = [lines[header + 1].split(), lines[header + 2].split()]
    assert [row[0] for row in rows] == ["1", "8"]
    samples = [int(row[2]) for row in rows]
    # A lower threshold refines at least as much as a higher one (same seed, same scene).
    assert samples[0] >= samples[1] > 0
    rmse = [float(row[-5]) for row in rows]
    assert all(0.0 <= value < 0.2 for value in rmse)
    assert "map vs map" in result.stdout
    assert "rubber (regions[0])" in result.stdout
    assert (tmp_path / "lab" / "surfmap.db").exists()
