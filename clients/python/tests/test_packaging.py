"""The package as people install and use it, in fresh processes without
PYTHONPATH: in place from clients/python, installed with
``pip install --no-deps --no-build-isolation -e`` into a venv that sees
Debian's packages, and the message when the generated stubs are missing."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Dict, List

PACKAGE_ROOT = Path(__file__).resolve().parents[1]      # clients/python
PROBE = ("import surfmap_client as sc, surfmap_client._stubs as st; "
         "print(sc.__file__); print(st.pb.__file__); print(sc.SurfmapClient.list_job_events.__name__)")


def clean_env(**extra: str) -> Dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(extra)
    return env


def run(command: List[str], cwd: Path, env: Dict[str, str], timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=str(cwd), env=env, capture_output=True, text=True, timeout=timeout)


def test_used_in_place_without_pythonpath():
    result = run([sys.executable, "-c", PROBE], PACKAGE_ROOT, clean_env())
    assert result.returncode == 0, result.stderr
    package_file, stub_file, method = result.stdout.split()
    assert Path(package_file).parent == PACKAGE_ROOT / "surfmap_client"
    assert stub_file.endswith("surfmap/v1/surfmap_pb2.py")
    assert method == "list_job_events"


def test_installed_editable_into_a_venv(tmp_path):
    venv = tmp_path / "venv"
    made = run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], tmp_path, clean_env())
    assert made.returncode == 0, f"python3 -m venv failed (Debian package python3-venv):\n{made.stderr}"
    python = venv / "bin" / "python"
    installed = run([str(python), "-m", "pip", "install", "--no-deps", "--no-build-isolation", "--no-index",
                     "--disable-pip-version-check", "-e", str(PACKAGE_ROOT)], tmp_path, clean_env(), timeout=300)
    assert installed.returncode == 0, installed.stdout + installed.stderr
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    result = run([str(python), "-c", PROBE + "; import importlib.metadata as m; print(m.version('surfmap-client'))"],
                 elsewhere, clean_env())
    assert result.returncode == 0, result.stderr
    package_file, _, _, version = result.stdout.split()
    assert Path(package_file).parent == PACKAGE_ROOT / "surfmap_client", "editable: the source tree's package"
    assert version == "0.2.0"
    assert (PACKAGE_ROOT / "surfmap_client" / "py.typed").is_file()
    assert not list(PACKAGE_ROOT.glob("*.egg-info")), "the install leaves nothing in the source tree"


def test_a_wrong_stubs_directory_is_named():
    result = run([sys.executable, "-c", "import surfmap_client"], PACKAGE_ROOT,
                 clean_env(SURFMAP_PYTHON_STUBS="/nonexistent/gen"))
    assert result.returncode != 0
    assert "SURFMAP_PYTHON_STUBS=/nonexistent/gen has no surfmap/v1/surfmap_pb2.py" in result.stderr


def test_missing_stubs_say_how_to_build_them(tmp_path):
    # A copy of the package outside any source tree with a build/ directory.
    copy = tmp_path / "checkout" / "clients" / "python"
    shutil.copytree(PACKAGE_ROOT / "surfmap_client", copy / "surfmap_client",
                    ignore=shutil.ignore_patterns("__pycache__"))
    env = clean_env()
    env.pop("SURFMAP_PYTHON_STUBS", None)
    result = run([sys.executable, "-c", "import surfmap_client"], copy, env)
    assert result.returncode != 0
    assert "needs the Python stubs generated from proto/surfmap/v1/surfmap.proto" in result.stderr
    assert "cmake --build build --target surfmap_python_stubs" in result.stderr
    assert str(tmp_path / "checkout" / "build" / "clients" / "python" / "gen") in result.stderr
