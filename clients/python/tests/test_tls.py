"""TLS: a surfmapd with tls_cert_file/tls_key_file (a throw-away CA and a
server certificate for 127.0.0.1 made here by the openssl command) and
tokens. connect(ca_file=...) works and the roles hold; a plaintext client and
a client trusting another CA cannot connect."""

from __future__ import annotations

import json
import subprocess

import grpc
import pytest

import surfmap_client as sc
from surfmap_client.local_processes import LocalServer

READ = "py-tls-read-token-000001"
STEER = "py-tls-steer-token-00001"


def _openssl(directory, *args: str) -> None:
    subprocess.run(["openssl", *args], cwd=directory, check=True, capture_output=True)


@pytest.fixture(scope="module")
def pki(tmp_path_factory):
    d = tmp_path_factory.mktemp("pki")
    _openssl(d, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out", "ca.pem", "-days", "2",
             "-subj", "/CN=py-test-ca")
    _openssl(d, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "wrong.key", "-out", "wrong-ca.pem",
             "-days", "2", "-subj", "/CN=py-wrong-ca")
    (d / "server.ext").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    _openssl(d, "req", "-newkey", "rsa:2048", "-nodes", "-keyout", "server.key", "-out", "server.csr",
             "-subj", "/CN=localhost")
    _openssl(d, "x509", "-req", "-in", "server.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
             "-out", "server.pem", "-days", "2", "-extfile", "server.ext")
    return d


@pytest.fixture(scope="module")
def tls_server(lab, pki, tmp_path_factory):
    directory = tmp_path_factory.mktemp("surfmapd-tls")
    config = directory / "surfmapd.json"
    config.write_text(json.dumps({"tls_cert_file": str(pki / "server.pem"), "tls_key_file": str(pki / "server.key"),
                                  "tokens": {READ: "read", STEER: "steer"}}))
    with LocalServer(lab.surfmapd, str(directory / "surfmap.db"), str(directory / "surfmapd.log"),
                     config_path=str(config)) as running:
        yield running


def test_ca_file_connects_and_roles_hold(tls_server, pki, lab):
    with sc.connect(tls_server.address, timeout=10.0, token=STEER, ca_file=pki / "ca.pem") as steer, \
            sc.connect(tls_server.address, timeout=10.0, token=READ, ca_file=str(pki / "ca.pem")) as reader:
        obj = steer.upload_object(lab.mesh(), name="over-tls")
        assert [o.object_id for o in reader.list_objects()] == [obj.object_id]
        with pytest.raises(sc.SurfmapError) as caught:
            reader.upload_object(lab.mesh())
        assert caught.value.code == grpc.StatusCode.PERMISSION_DENIED


def test_plaintext_and_a_wrong_ca_cannot_connect(tls_server, pki):
    for ca_file in (None, pki / "wrong-ca.pem"):
        with pytest.raises(sc.SurfmapError) as caught:
            sc.connect(tls_server.address, timeout=3.0, token=READ, ca_file=ca_file)
        assert caught.value.code == grpc.StatusCode.UNAVAILABLE


def test_ca_file_and_root_certificates_together_are_refused(pki):
    with pytest.raises(sc.SurfmapError) as caught:
        sc.connect("127.0.0.1:1", ca_file=pki / "ca.pem", root_certificates=b"x")
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
