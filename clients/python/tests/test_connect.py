"""Connecting: unreachable servers and bad arguments give SurfmapError, never a hang."""

from __future__ import annotations

import socket

import grpc
import pytest

import surfmap_client as sc


def unused_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_unreachable_server_is_unavailable_within_the_timeout():
    address = f"127.0.0.1:{unused_port()}"
    with pytest.raises(sc.SurfmapError) as caught:
        sc.connect(address, timeout=0.5)
    assert caught.value.code == grpc.StatusCode.UNAVAILABLE
    assert address in caught.value.message
    # Without waiting, the first call fails instead (by its deadline at the latest).
    with sc.connect(address, timeout=0.5, wait_ready=False) as client:
        with pytest.raises(sc.SurfmapError) as caught:
            client.list_objects()
        assert caught.value.code in (grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.DEADLINE_EXCEEDED)
        assert caught.value.method == "ListObjects"


def test_timeout_must_be_positive():
    with pytest.raises(sc.SurfmapError) as caught:
        sc.connect("127.0.0.1:1", timeout=0)
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT


def test_connected_client_knows_its_address(server, client):
    assert client.address == server.address
    assert client.timeout == pytest.approx(20.0)
