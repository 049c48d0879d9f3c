"""The rig's trace spool (no server): the file format surfmap-rig shares, its
checks, the directory's life (add, pending, remove, reject), the lock."""

from __future__ import annotations

import os
import struct
from typing import Any, Dict

import grpc
import numpy as np
import pytest

import surfmap_client as sc
from surfmap_client.probe import ProbeCommand
from surfmap_client.records import Phase, ProbeParameters
from surfmap_client.spool import (SpoolHeader, TraceSpool, default_spool_dir, format_spool_file, parse_spool_file,
                                  rig_id_path_component)


def command(command_id: int = 17) -> ProbeCommand:
    return ProbeCommand(command_id, 3, 0, 12, np.zeros(3), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]),
                        ProbeParameters(20.0, 10.0, 5.0), 1, None)


def awkward_trace(command_id: int = 17) -> sc.Trace:
    """Values that need 17 digits, a subnormal and a negative zero."""
    values = [0.1, 1.0 / 3.0, -2.718281828459045, 5e-324, -0.0, 123456789.12345678]
    t = [0.01 * i + 1e-9 for i in range(6)]
    xyz = [[values[i], -values[(i + 1) % 6], values[(i + 2) % 6]] for i in range(6)]
    f = [[values[(i + 3) % 6], values[(i + 4) % 6], 5.0 + values[(i + 5) % 6]] for i in range(6)]
    return sc.measured_trace(command(command_id), t, xyz, f, ["fwd", "fwd", "pause", "rev", "rev", "rev"])


def header(command_id: int = 17, measured_ms: int = 1795000000123, rig_id: str = "lab arm #1") -> SpoolHeader:
    return SpoolHeader(command_id, 3, 2, rig_id, measured_ms)


def bits(array: np.ndarray) -> list:
    return [struct.pack("<d", float(v)) for v in np.asarray(array, dtype=float).ravel()]


def test_the_file_is_the_documented_format_and_reads_back_bit_for_bit():
    trace = awkward_trace()
    text = format_spool_file(header(), trace)
    assert text.startswith("# surfmap spooled trace v1\n# command_id: 17\n# job_id: 3\n# attempt: 2\n"
                           "# rig_id: lab arm #1\n# measured_unix_ms: 1795000000123\nt,x,y,z,fx,fy,fz,phase\n")
    read_header, read = parse_spool_file(text, "f.csv")
    assert read_header == header()
    assert bits(read.t) == bits(trace.t)
    assert bits(read.xyz) == bits(trace.xyz)
    assert bits(read.f) == bits(trace.f)
    assert read.phase.tolist() == [Phase.FORWARD] * 2 + [Phase.PAUSE] + [Phase.REVERSE] * 3
    assert (read.command_id, read.job_id, read.trace_id) == (17, 3, 0)


def test_a_file_as_surfmap_rig_writes_it_is_read():
    # C++ writes the shortest round-trip text too, with its own spelling ("0", "1e-05").
    text = ("# surfmap spooled trace v1\n# command_id: 5\n# job_id: 1\n# attempt: 1\n# rig_id: sim-plate-77\n"
            "# measured_unix_ms: 1000\nt,x,y,z,fx,fy,fz,phase\n0,0,0,0,-1.5,0,5,fwd\n0.01,1e-05,0,0,0,0,5,pause\n"
            "0.02,0,0,-0,1.5,0,5,rev\n")
    read_header, trace = parse_spool_file(text, "cpp.csv")
    assert read_header.rig_id == "sim-plate-77"
    assert trace.xyz[1, 0] == 1e-05
    assert np.signbit(trace.xyz[2, 2])


def test_a_rig_frame_trace_keeps_its_frame_and_registration():
    rig_header = SpoolHeader(17, 3, 2, "lab arm #1", 1795000000123, "rig_base_sensor_forces", 7)
    text = format_spool_file(rig_header, awkward_trace())
    assert ("# measured_unix_ms: 1795000000123\n# frame: rig_base_sensor_forces\n# registration_id: 7\n"
            "t,x,y,z") in text
    assert parse_spool_file(text, "f.csv")[0] == rig_header
    # A file from before frames (no keys): the object's frame.
    old_header, _ = parse_spool_file(format_spool_file(header(), awkward_trace()), "old.csv")
    assert (old_header.frame, old_header.registration_id) == ("object", 0)
    # The file surfmap-rig writes for the same header reads the same.
    cpp = ("# surfmap spooled trace v1\n# command_id: 5\n# job_id: 1\n# attempt: 1\n# rig_id: r\n"
           "# measured_unix_ms: 1000\n# frame: rig_base\n# registration_id: 4\nt,x,y,z,fx,fy,fz,phase\n"
           "0,0,0,0,-1.5,0,5,fwd\n0.01,1e-05,0,0,0,0,5,pause\n0.02,0,0,-0,1.5,0,5,rev\n")
    assert parse_spool_file(cpp, "cpp.csv")[0] == SpoolHeader(5, 1, 1, "r", 1000, "rig_base", 4)
    for edit, message in [
            (lambda s: s.replace("rig_base_sensor_forces", "tool"),
             'f:7: frame: unknown trace frame "tool"; expected object, rig_base or rig_base_sensor_forces'),
            (lambda s: s.replace("# registration_id: 7\n", ""),
             "f:8: expected '# registration_id: <value>' after the frame, found 't,x,y,z,fx,fy,fz,phase'"),
            (lambda s: s.replace("# registration_id: 7", "# registration_id: x"),
             "f:8: registration_id 'x' is not an integer"),
            (lambda s: s.replace("rig_base_sensor_forces", "object"),
             "f:2: header: registration_id 7 with the object's frame (a registration is for a rig frame)")]:
        with pytest.raises(sc.SurfmapError) as error:
            parse_spool_file(edit(text), "f")
        assert error.value.message == message
    with pytest.raises(sc.SurfmapError, match="registration_id 7 with the object's frame"):
        format_spool_file(SpoolHeader(17, 3, 2, "r", 1, "object", 7), awkward_trace())


@pytest.mark.parametrize("edit, message", [
    (lambda s: "t,x\n", "f:1: not a spool file: the first line must be '# surfmap spooled trace v1'"),
    (lambda s: s.replace("# job_id: 3\n", ""), "f:3: expected '# job_id: <value>', found '# attempt: 2'"),
    (lambda s: s.replace("# job_id: 3", "# job_id: three"), "f:3: job_id 'three' is not an integer"),
    (lambda s: s.replace("# job_id: 3", "# job_id: -3"), "f:2: header: job_id -3 is not a job id (> 0)"),
    (lambda s: s.replace(",rev\n", ",sideways\n", 1), "f:11: unknown phase 'sideways'"),
    (lambda s: s.replace(",pause\n", ",rev\n").replace("rev\n", "fwd\n", 3).replace("fwd\n", "rev\n", 1),
     "f:7: trace: phase["),
])
def test_parse_errors_name_the_line(edit, message):
    with pytest.raises(sc.SurfmapError) as error:
        parse_spool_file(edit(format_spool_file(header(), awkward_trace())), "f")
    assert error.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert error.value.message.startswith(message), error.value.message


@pytest.mark.parametrize("change, message", [
    (dict(t=[0.0, 0.0, 0.1]), "trace: t[1] = 0.0 does not increase (t[0] = 0.0)"),
    (dict(f=[[0, 0, 5], [0, float("nan"), 5], [0, 0, 5]]), "trace: f[1, 1] is not finite"),
    (dict(xyz=[[0, 0, 0], [1, 0, 0]]), "trace: xyz must have shape (3, 3) like t, got (2, 3)"),
    (dict(phase=["rev", "pause", "fwd"]), "trace: phase[1] is PAUSE after REVERSE: phases must run forward, pause, "
                                          "reverse"),
    (dict(phase=["fwd", "pause", "pause"]), "trace: no reverse sample"),
])
def test_check_trace_names_what_is_wrong(change, message):
    columns: Dict[str, Any] = dict(t=[0.0, 0.1, 0.2], xyz=[[0, 0, 0], [1, 0, 0], [0, 0, 0]],
                                   f=[[-1, 0, 5], [0, 0, 5], [1, 0, 5]], phase=["fwd", "pause", "rev"])
    columns.update(change)
    trace = sc.measured_trace(command(), **columns)
    with pytest.raises(sc.SurfmapError) as error:
        sc.check_trace(trace)
    assert error.value.message == message
    with pytest.raises(sc.SurfmapError, match="is not 'fwd', 'pause' or 'rev'"):
        sc.measured_trace(command(), [0.0], [[0, 0, 0]], [[0, 0, 5]], ["forward"])


def test_add_pending_remove_and_reject(tmp_path):
    with TraceSpool.open(tmp_path / "spool") as spool:
        second = spool.add(header(8, 2000), awkward_trace(8))
        first = spool.add(header(9, 1000), awkward_trace(9))
        assert first.name == "0000000001000-command-9.trace.csv"
        assert spool.pending() == [first, second], "oldest first"
        again = spool.add(header(9, 1000), awkward_trace(9))
        assert again.name == "0000000001000-command-9-2.trace.csv"
        spool.remove(again)
        assert spool.read(second).header.command_id == 8
        spool.remove(first)
        kept = spool.reject(second, "ALREADY_EXISTS: command 8 was measured by rig 'b'")
        assert kept == spool.rejected_dir / second.name
        assert spool.pending() == []
        reason = (spool.rejected_dir / (second.name + ".reason")).read_text()
        assert reason.startswith("ALREADY_EXISTS: command 8 was measured by rig 'b'\nrejected_unix_ms: ")
        with pytest.raises(sc.SurfmapError, match="is not a file of the spool"):
            spool.remove(kept)


def test_one_process_per_spool_and_leftover_temp_files_go(tmp_path):
    (tmp_path / ".tmp-0000000001000-command-3.trace.csv.123").write_text("half a trace")
    first = TraceSpool.open(tmp_path)
    assert not (tmp_path / ".tmp-0000000001000-command-3.trace.csv.123").exists()
    with pytest.raises(sc.SurfmapError) as error:
        TraceSpool.open(tmp_path)
    assert error.value.code == grpc.StatusCode.FAILED_PRECONDITION
    assert "is in use by another rig process" in error.value.message
    first.close()
    TraceSpool.open(tmp_path).close()


def test_empty_directories_are_removed_at_the_end(tmp_path):
    with TraceSpool.open(tmp_path / "a") as spool:
        spool.remove_directories_if_empty()
    assert not (tmp_path / "a").exists()
    with TraceSpool.open(tmp_path / "b") as spool:
        spool.add(header(), awkward_trace())
        spool.remove_directories_if_empty()
    assert (tmp_path / "b").exists() and not (tmp_path / "b" / "rejected").exists()


def test_the_default_directory_is_surfmap_rigs(monkeypatch):
    assert rig_id_path_component("lab-arm_1.b") == "lab-arm_1.b"
    assert rig_id_path_component("lab/arm 1") == "lab%2Farm%201"
    assert rig_id_path_component("..") == "%2E%2E"
    assert rig_id_path_component("é") == "%C3%A9"
    monkeypatch.setenv("XDG_STATE_HOME", "/var/lab/state")
    assert str(default_spool_dir("arm/1")) == "/var/lab/state/surfmap/spool/arm%2F1"
    monkeypatch.setenv("XDG_STATE_HOME", "relative/ignored")
    monkeypatch.setenv("HOME", "/home/lab")
    assert str(default_spool_dir("arm")) == "/home/lab/.local/state/surfmap/spool/arm"
    monkeypatch.delenv("XDG_STATE_HOME")
    monkeypatch.delenv("HOME")
    with pytest.raises(sc.SurfmapError) as error:
        default_spool_dir("arm")
    assert error.value.code == grpc.StatusCode.FAILED_PRECONDITION
    assert os.environ.get("HOME") is None
