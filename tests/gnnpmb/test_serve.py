"""``gnnpmb-viz --serve`` in a real process without a display: the web viewer answers on its port, the gRPC port
is open, both listen on localhost only (issue 33, case 14), the URL is printed, and Ctrl-C ends the run with exit
code 0 and both ports closed."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from gnnpmb.errors import GnnpmbError
from gnnpmb.serve import ServeTarget, check_bind, check_display

BIN = Path(sys.executable).parent
LINUX_TCP_TABLES = Path("/proc/net/tcp").exists()


def _free_ports(n: int) -> list[int]:
    """``n`` distinct free ports: all bound at once, so that two calls cannot hand out the same port twice."""
    sockets = [socket.socket() for _ in range(n)]
    try:
        for sock in sockets:
            sock.bind(("127.0.0.1", 0))
        return [sock.getsockname()[1] for sock in sockets]
    finally:
        for sock in sockets:
            sock.close()


def _listening(port: int) -> list[str]:
    """The local addresses (hex, as /proc/net/tcp* shows them) listening on TCP ``port``."""
    out = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as f:
            for line in f.readlines()[1:]:
                fields = line.split()
                address, port_hex = fields[1].split(":")
                if int(port_hex, 16) == port and fields[3] == "0A":
                    out.append(address)
    return out


def test_serve_prints_the_url_serves_the_viewer_and_stops_on_ctrl_c(demo_dataroot: Path) -> None:
    target = ServeTarget(*_free_ports(2))
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    argv = [str(BIN / "gnnpmb-viz"), "scene-0103", "--dataroot", str(demo_dataroot), "--tracker", "gnn"]
    argv += ["--frames", "0:2", "--no-failures", "--no-progress", "--serve"]
    argv += ["--web-port", str(target.web_port), "--grpc-port", str(target.grpc_port)]
    proc = subprocess.Popen(
        argv,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        lines = []
        while not (lines and lines[-1].startswith("serving")):
            line = proc.stderr.readline()
            assert line, f"ended early: {lines}"
            lines.append(line)
        assert lines[0].strip() == f"web viewer: {target.url}"
        page = urllib.request.urlopen(f"http://localhost:{target.web_port}/", timeout=30).read()
        assert b"<html" in page.lower()
        socket.create_connection(("localhost", target.grpc_port), timeout=10).close()
        if LINUX_TCP_TABLES:
            for port in (target.web_port, target.grpc_port):
                assert _listening(port) == ["0100007F"], (port, _listening(port))  # 127.0.0.1, nothing else
    finally:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert out.strip().endswith(f"served at {target.url}")
    if LINUX_TCP_TABLES:  # the web viewer's process ended with the run
        assert _listening(target.web_port) == [] and _listening(target.grpc_port) == []


def test_url_points_the_viewer_at_the_grpc_server() -> None:
    assert ServeTarget(9090, 9876).url == "http://127.0.0.1:9090/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9876%2Fproxy"
    assert ServeTarget(9090, 9876, "::1").url.startswith("http://[::1]:9090/?url=rerun%2Bhttp%3A%2F%2F%5B%3A%3A1%5D")


@pytest.mark.parametrize(
    ("bind", "warned"), [("127.0.0.1", False), ("::1", False), ("0.0.0.0", True), ("::", True), ("10.1.2.3", True)]
)
def test_only_a_bind_address_beyond_this_machine_is_warned_about(bind: str, warned: bool) -> None:
    warning = ServeTarget(9090, 9876, check_bind(bind)).exposure_warning()
    assert (warning is not None) == warned
    if warned:
        assert warning.startswith(f"warning: --bind {bind} serves the viewer and the recording's data")


def test_a_bind_address_is_an_ip_address() -> None:
    assert check_bind("[::1]") == "::1"
    with pytest.raises(GnnpmbError, match="--bind localhost: not an IP address"):
        check_bind("localhost")


def test_no_display_is_refused_on_linux(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(GnnpmbError, match="--save OUT.rrd .* --serve"):
        check_display()
    monkeypatch.setenv("WAYLAND_DISPLAY", "wayland-0")
    check_display()
