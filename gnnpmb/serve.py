"""Where a live ``gnnpmb-viz`` run is shown: the spawned native viewer needs a display; ``--serve`` serves the
Rerun web viewer instead (HTTP on ``web_port``) reading the recording from an in-process gRPC server
(``grpc_port``), and prints the URL to open (on a remote machine: forward both ports, e.g. ``ssh -L``).

Both ports listen on ``bind``: the loopback address 127.0.0.1 unless ``--bind ADDRESS`` asks for another (which
serves the recording to whoever can reach that address; the command line warns). A port counts as in use when it
is taken on the bind address or, for loopback, on IPv6's ``::1`` too (a browser may resolve "localhost" to
either).

This module checks the request (ports, display); ``viz.serving`` opens the served stream.
"""

from __future__ import annotations

import errno
import ipaddress
import os
import socket
import sys
from dataclasses import dataclass
from urllib.parse import quote

from gnnpmb.errors import GnnpmbError

DEFAULT_WEB_PORT = 9090
DEFAULT_GRPC_PORT = 9876
"""Rerun's own defaults for the web viewer's HTTP port and the gRPC data port."""
DEFAULT_BIND = "127.0.0.1"
"""Where ``--serve`` listens unless ``--bind`` says otherwise: this machine only."""


@dataclass(frozen=True, slots=True)
class ServeTarget:
    """The two TCP ports of ``--serve``: the web viewer's HTTP port and the gRPC port it reads data from, both
    listening on the IP address ``bind``."""

    web_port: int
    grpc_port: int
    bind: str = DEFAULT_BIND

    @property
    def is_local(self) -> bool:
        """Whether only this machine can connect (a loopback bind address)."""
        return ipaddress.ip_address(self.bind).is_loopback

    @property
    def host(self) -> str:
        """The host part of the URLs: the bind address (IPv6 in brackets), or 127.0.0.1 for an any-address bind
        (0.0.0.0, ::)."""
        address = ipaddress.ip_address(self.bind)
        if address.is_unspecified:
            return "127.0.0.1"
        return f"[{address}]" if address.version == 6 else str(address)

    @property
    def grpc_uri(self) -> str:
        return f"rerun+http://{self.host}:{self.grpc_port}/proxy"

    @property
    def url(self) -> str:
        """The URL to open in a browser: the web viewer, told where the data is."""
        return f"http://{self.host}:{self.web_port}/?url={quote(self.grpc_uri, safe='')}"

    def exposure_warning(self) -> str | None:
        """The warning line for a bind address that other machines can reach, or None for loopback."""
        if self.is_local:
            return None
        return (
            f"warning: --bind {self.bind} serves the viewer and the recording's data on ports {self.web_port} and "
            f"{self.grpc_port} to every machine that can reach this address; without --bind only this machine can"
        )


def check_bind(address: str) -> str:
    """``address`` as a canonical IP address, or a GnnpmbError saying what ``--bind`` takes."""
    try:
        return str(ipaddress.ip_address(address.strip("[]")))
    except ValueError:
        raise GnnpmbError(
            f"--bind {address}: not an IP address; give e.g. 127.0.0.1 (this machine only, the default), "
            "0.0.0.0 (every IPv4 interface) or :: (every interface)"
        ) from None


def _probe_addresses(bind: str) -> list[tuple[socket.AddressFamily, str]]:
    """Where a port must be free for ``bind``: the address itself, plus ``::1`` for loopback and ``::`` for
    0.0.0.0 (the other family's twin, when this machine has IPv6)."""
    address = ipaddress.ip_address(bind)
    family = socket.AF_INET6 if address.version == 6 else socket.AF_INET
    out = [(family, str(address))]
    if socket.has_ipv6 and address.version == 4 and (address.is_loopback or address.is_unspecified):
        out.append((socket.AF_INET6, "::1" if address.is_loopback else "::"))
    if address.version == 6 and address.is_loopback:
        out.append((socket.AF_INET, "127.0.0.1"))
    return out


def check_display() -> None:
    """On Linux, a GnnpmbError unless an X11 or Wayland display is set: the spawned viewer needs one (without it,
    Rerun waits for a viewer that never starts and the run hangs)."""
    if not sys.platform.startswith("linux"):
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    raise GnnpmbError(
        "no display (DISPLAY and WAYLAND_DISPLAY are unset), so the Rerun viewer cannot open; write a recording "
        "with --save OUT.rrd (open it later with 'rerun OUT.rrd') or serve the web viewer with --serve"
    )


def check_serve_ports(target: ServeTarget) -> None:
    """A GnnpmbError naming the option if a port is out of range, the two are equal, or one is in use."""
    for option, port in (("--web-port", target.web_port), ("--grpc-port", target.grpc_port)):
        if not 1 <= port <= 65535:
            raise GnnpmbError(f"{option} {port}: a TCP port is a number from 1 to 65535")
    if target.web_port == target.grpc_port:
        raise GnnpmbError(f"--web-port and --grpc-port are both {target.web_port}; give them different ports")
    for option, port in (("--web-port", target.web_port), ("--grpc-port", target.grpc_port)):
        for family, address in _probe_addresses(target.bind):
            with socket.socket(family, socket.SOCK_STREAM) as probe:
                if family == socket.AF_INET6:
                    probe.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
                try:
                    probe.bind((address, port))
                except OSError as exc:
                    if exc.errno == errno.EADDRNOTAVAIL and address in ("::1", "::"):
                        continue  # no IPv6 on this machine: nothing can listen there either
                    reason = "is in use" if exc.errno == errno.EADDRINUSE else f"cannot be opened ({exc.strerror})"
                    raise GnnpmbError(
                        f"{option} {port}: the port {reason} on {address} (another gnnpmb-viz --serve or Rerun "
                        f"viewer?); pass {option} with a free port"
                    ) from None


def serve_target(serve: bool, web_port: int, grpc_port: int, bind: str | None) -> ServeTarget | None:
    """The ``--serve`` target (None without it); ``--bind`` without ``--serve`` is an error."""
    if not serve:
        if bind is not None:
            raise GnnpmbError("--bind only applies with --serve; add --serve or drop --bind")
        return None
    return ServeTarget(web_port, grpc_port, check_bind(bind) if bind is not None else DEFAULT_BIND)
