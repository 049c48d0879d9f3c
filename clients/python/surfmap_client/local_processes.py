"""Running surfmapd and surfmap-rig as local processes (examples and tests).

``LocalServer`` starts surfmapd on 127.0.0.1 with a free port (``--listen
127.0.0.1:0 --port-file``) and a given SQLite file, as scripts/demo.sh does,
and stops it with SIGTERM (then SIGKILL after a grace period).
``run_simulated_rig`` runs ``surfmap-rig --sim SCENE`` against a job until the
job ends; ``score_map`` runs ``surfmap-rig score`` (a map file against the
scene's truth). Failures raise ``LocalProcessError`` with the process's output.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path
from typing import List, Optional, Sequence


class LocalProcessError(RuntimeError):
    """A local surfmapd / surfmap-rig could not be found, started or did not succeed."""


def find_binary(name: str, env_var: str, explicit: Optional[str] = None) -> str:
    """``explicit``, else ``$env_var``, else ``name`` on PATH; LocalProcessError if none is an executable file."""
    candidates = [c for c in (explicit, os.environ.get(env_var)) if c]
    for candidate in candidates:
        if os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
        raise LocalProcessError(f"{name}: '{candidate}' is not an executable file")
    found = shutil.which(name)
    if found:
        return found
    raise LocalProcessError(f"{name} not found: pass its path or set {env_var}")


class LocalServer:
    """surfmapd on 127.0.0.1:<free port>. Use as a context manager."""

    def __init__(self, surfmapd: str, db_path: str, log_path: str, config_path: Optional[str] = None,
                 start_timeout_s: float = 30.0, port: int = 0) -> None:
        self.surfmapd = surfmapd
        self.listen_port = port   # 0: a free port; restart() reuses the last one
        self.db_path = db_path
        self.log_path = log_path
        self.config_path = config_path
        self.start_timeout_s = start_timeout_s
        self.port: Optional[int] = None
        self._process: Optional[subprocess.Popen] = None

    @property
    def address(self) -> str:
        if self.port is None:
            raise LocalProcessError("surfmapd is not running")
        return f"127.0.0.1:{self.port}"

    def start(self) -> "LocalServer":
        port_file = Path(self.db_path + ".port")
        port_file.unlink(missing_ok=True)
        command = [self.surfmapd, "--listen", f"127.0.0.1:{self.listen_port}", "--db", self.db_path,
                   "--port-file", str(port_file),
                   "--log-format", "text"]
        if self.config_path:
            command += ["--config", self.config_path]
        with open(self.log_path, "ab") as log:
            self._process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + self.start_timeout_s
        while time.monotonic() < deadline:
            if self._process.poll() is not None:
                raise LocalProcessError(f"surfmapd exited with code {self._process.returncode} during start-up; "
                                        f"its log ({self.log_path}):\n{self.log()}")
            try:
                text = port_file.read_text().strip()
                if text:
                    self.port = int(text)
                    self.listen_port = self.port
                    return self
            except (OSError, ValueError):
                pass  # not written yet, or half-written
            time.sleep(0.05)
        self.stop()
        raise LocalProcessError(f"surfmapd did not write {port_file} within {self.start_timeout_s:g} s; "
                                f"its log:\n{self.log()}")

    def stop(self, grace_s: float = 15.0) -> Optional[int]:
        """SIGTERM, then SIGKILL after ``grace_s``; returns the exit code (None if never started)."""
        process, self._process = self._process, None
        if process is None:
            return None
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(timeout=grace_s)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        self.port = None
        return process.returncode

    def kill(self) -> None:
        """SIGKILL (the crash case: nothing flushed, no shutdown code runs)."""
        process, self._process = self._process, None
        if process is not None and process.poll() is None:
            process.kill()
            process.wait()
        self.port = None

    def restart(self) -> "LocalServer":
        """Starts the stopped server again on the same database and port
        (clients holding the address reconnect)."""
        if self._process is not None:
            raise LocalProcessError("restart: surfmapd is still running")
        return self.start()

    def log(self) -> str:
        try:
            return Path(self.log_path).read_text(errors="replace")
        except OSError:
            return "(no log)"

    def __enter__(self) -> "LocalServer":
        return self.start() if self._process is None else self

    def __exit__(self, *exc) -> None:
        self.stop()


def rig_command(rig: str, address: str, scene: str, job_id: int, rig_id: str, token: Optional[str] = None,
                extra: Sequence[str] = ()) -> List[str]:
    command = [rig, "--server", address, "--sim", scene, "--job", str(job_id), "--rig-id", rig_id, "--quiet"]
    if token:
        command += ["--token", token]
    return command + list(extra)


def run_simulated_rigs(rig: str, address: str, scene: str, job_id: int, count: int = 1,
                       token: Optional[str] = None, timeout_s: float = 600.0) -> List[str]:
    """Runs ``count`` simulated rigs on the job until it ends; returns each rig's summary line.

    LocalProcessError when a rig fails or outlives ``timeout_s``."""
    processes = [subprocess.Popen(rig_command(rig, address, scene, job_id, f"py-rig-{i + 1}", token),
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                 for i in range(count)]
    summaries: List[str] = []
    deadline = time.monotonic() + timeout_s
    try:
        for process in processes:
            try:
                output, _ = process.communicate(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                raise LocalProcessError(f"surfmap-rig did not finish job {job_id} within {timeout_s:g} s") from None
            if process.returncode != 0:
                raise LocalProcessError(f"surfmap-rig exited with code {process.returncode}:\n{output}")
            summaries.append(output.strip().splitlines()[-1] if output.strip() else "")
    finally:
        for process in processes:
            if process.poll() is None:
                process.terminate()
                process.wait()
    return summaries


def score_map(rig: str, scene: str, map_json_path: str, timeout_s: float = 120.0) -> dict:
    """``surfmap-rig score --sim SCENE --map FILE --json -``: the map against the scene's truth, as a dict."""
    result = subprocess.run([rig, "score", "--sim", scene, "--map", map_json_path, "--json", "-"],
                            capture_output=True, text=True, timeout=timeout_s)
    if result.returncode != 0:
        raise LocalProcessError(f"surfmap-rig score exited with code {result.returncode}:\n"
                                f"{result.stdout}{result.stderr}")
    try:
        return json.loads(result.stdout)
    except json.JSONDecodeError as error:
        raise LocalProcessError(f"surfmap-rig score printed no JSON ({error}):\n{result.stdout}") from None
