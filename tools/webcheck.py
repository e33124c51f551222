"""A real-browser check of a saved recording: serve it with Rerun's web viewer, open it in headless Chromium
and screenshot it once the viewer has taken in the whole recording and the 3D views show the scene.

The recording is served over HTTP from a thread of this process and ``rerun URL --serve-web`` hosts the web viewer that
opens it (both bound to 127.0.0.1, on free ports). Not ``rerun FILE.rrd --serve-web``: its gRPC proxy spins on one core
while idle (Rerun 0.41, rerun-io/rerun#10944; 65 s of CPU in one check here), which a 2-core machine rendering WebGL in
software cannot spare. Chromium runs headless with WebGL2 on SwiftShader (no GPU) and a fresh profile; it is driven over
the DevTools protocol (``websocket-client``): navigate at a small viewport (``LOADING_VIEWPORT``), poll the viewer's
state every few seconds without screenshots until it shows everything loaded, screenshot until the small views look
rendered, then resize to the full viewport and screenshot until ready. Ready means, in this order: the viewer's own
state (``WebHandle.viewer_state()``, read with ``read_viewer_state``) shows the recording open with every view of its
blueprint and every timeline of the file loaded to its last time; the viewer's ingestion-backlog readout is gone; and
the 3D-view regions hold many varied, non-background pixels (LiDAR points, coloured boxes) in two shots in a row. Pixels
alone are not enough: panels can still be empty while the 3D views look finished. Both servers run in their own process
groups and are killed (group-wide) on every exit path; the file server stops with the check.

By hand: ``uv run python -m tools.webcheck FILE.rrd --out shot.png [--views N]`` (default: the runs the recording's
blueprint lays side by side, ``runs_side_by_side``).
"""

from __future__ import annotations

import argparse
import base64
import contextlib
import functools
import http.server
import io
import itertools
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gnnpmb.atomic import write_bytes

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_FLAGS: tuple[str, ...] = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
    "--disable-quic",
    "--hide-scrollbars",
    "--mute-audio",
)
"""Headless Chromium that renders WebGL2 on SwiftShader and talks to nothing but localhost."""

DEFAULT_VIEWPORT = (1920, 1080)
LOADING_VIEWPORT = (640, 360)
"""The page's size until the viewer's state shows everything loaded and a shot shows its views rendered at this size;
then it goes to the full viewport for the pixel checks that decide readiness and for the screenshot. Chromium renders
WebGL in software (SwiftShader's worker threads in its GPU process take nearly all its CPU) for as long as the viewer
draws, and at 1920x1080 each frame and shot costs more and the viewer takes longer to take the data in. Measured
(demo then focus recording in one browser, ``check_recording`` back to back on the shared 2-core machine; Chromium's
CPU seconds): small until loaded, then full: 79 vs 104, 80 vs 121 and 76 vs 90 at full size throughout; small until
rendered too (kept): 61 vs 90, 58 vs 95 and 58 vs 115 (wall 40-41 s vs 56-72 s)."""
SMALL_RENDER_WAIT_S = 30.0
"""Seconds after the viewer's state showed everything loaded that a small page may take to show its views rendered;
then the page goes to the full viewport anyway (readiness is decided there)."""
BACKGROUND_TOLERANCE = 12
"""A pixel is background when each channel is within this of the region's most common colour."""
SATURATION_MIN = 60
"""A pixel is coloured (a box, gate or label) when its channels spread by more than this; the LiDAR points,
grid and background are greys."""
MIN_FOREGROUND_FRACTION = 0.005
MIN_DISTINCT_COLORS = 200
MIN_COLORED_FRACTION = 0.001
SETTLED_SHOTS = 2
"""Ready: this many consecutive shots after the viewer's state showed everything loaded, with rendered views and
no ingestion backlog (``backlog_region``)."""
STATUS_X = (235, 500)
STATUS_Y = (6, 30)
"""Pixel span of the top bar (Rerun 0.41 web viewer) right of the renderer badge, where the viewer shows its
ingestion backlog ("123.4 s latency") while data is still streaming in; blank once everything has arrived.
The data may take minutes to arrive on SwiftShader, and the 3D views can stay unchanged for over half a
minute meanwhile, so an unchanged page alone does not mean it is complete."""
"""A rendered 3D view (LiDAR points, class- and track-coloured boxes, gates, labels) beats all three by far:
measured 18-20 % foreground, 2,000-10,000 colours and 1.3-1.9 % coloured pixels per view on the demo scene in a
focus recording. A full recording's bird's-eye view is sparse (boxes on a white ground, no LiDAR): 1.9 %
foreground, ~1,000 colours and 0.4 % coloured at frame 0 of the demo, so the foreground floor is low and the
colour count decides. The loading page and an empty view are a uniform background with a grid, a logo or a few
lines of text (under 40 colours); LiDAR alone, before the boxes have streamed in, has no coloured pixels.
Whether everything has arrived is the viewer's own state (``read_viewer_state``), not the pixels."""


VIEWER_STATE_JS = (
    "(() => { const h = window._handle; if (!h || !h.viewer_state) return null;"
    " const s = h.viewer_state(); let b = ''; for (const x of s) b += String.fromCharCode(x); return btoa(b); })()"
)
"""The web viewer's state (Rerun 0.41 ``WebHandle.viewer_state``: protobuf bytes), base64 over DevTools."""


def _varint(buf: bytes, i: int) -> tuple[int, int]:
    value, shift = 0, 0
    while True:
        byte = buf[i]
        i += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, i


def protobuf_fields(buf: bytes) -> list[tuple[int, int | bytes]]:
    """(field number, value) of one protobuf message: varints as int, length-delimited fields as bytes
    (fixed-width fields as their raw bytes). Raises ValueError on bytes that are not a message."""
    out: list[tuple[int, int | bytes]] = []
    i = 0
    while i < len(buf):
        key, i = _varint(buf, i)
        field, wire = key >> 3, key & 7
        if wire == 0:
            value, i = _varint(buf, i)
            out.append((field, value))
        elif wire == 2:
            size, i = _varint(buf, i)
            out.append((field, buf[i : i + size]))
            i += size
        elif wire in (1, 5):
            width = 8 if wire == 1 else 4
            out.append((field, buf[i : i + width]))
            i += width
        else:
            raise ValueError(f"protobuf wire type {wire} at byte {i}")
    if i != len(buf):
        raise ValueError("truncated protobuf message")
    return out


@dataclass(frozen=True, slots=True)
class ViewerState:
    """What the web viewer says it holds: the open recording ("Recording:<app>:<id>"), the names of the views
    it shows, and per timeline the last time it has data for."""

    recording: str | None
    views: frozenset[str]
    timeline_max: dict[str, int]


def read_viewer_state(buf: bytes) -> ViewerState:
    """Decode ``viewer_state()`` bytes (Rerun 0.41, read on this machine): field 3 is the open recording (1: its
    name; 2: its timelines, each 1: {1: name}, 3: {1: min, 2: max} of the data loaded so far); field 5 lists the
    views (3: display name). A value of 0 is not written at all (proto3), so a range with no max ends at 0: a
    focus recording of a failure at frame 0 was never seen loaded (dev set scene-0916 centerpoint miss:2)."""
    recording, views, maxima = None, set(), {}
    for field, value in protobuf_fields(buf):
        if field == 3 and isinstance(value, bytes):
            for sub, sub_value in protobuf_fields(value):
                if sub == 1 and isinstance(sub_value, bytes):
                    recording = sub_value.decode("utf-8", "replace")
                elif sub == 2 and isinstance(sub_value, bytes):
                    name, top = None, None
                    for key, item in protobuf_fields(sub_value):
                        if key == 1 and isinstance(item, bytes):
                            name = dict(protobuf_fields(item)).get(1, b"").decode()
                        elif key == 3 and isinstance(item, bytes):
                            top = dict(protobuf_fields(item)).get(2, 0)  # proto3 leaves out a 0
                    if name is not None and isinstance(top, int):
                        maxima[name] = top
        elif field == 5 and isinstance(value, bytes):
            name = dict(protobuf_fields(value)).get(3)
            if isinstance(name, bytes):
                views.add(name.decode("utf-8", "replace"))
    return ViewerState(recording, frozenset(views), maxima)


@dataclass(frozen=True, slots=True)
class Expected:
    """What a viewer that has taken in ``rrd`` must show: its recording, the views of its default blueprint and
    the last time of each sequence timeline."""

    recording: str
    views: frozenset[str]
    timeline_max: dict[str, int]

    def met_by(self, state: ViewerState) -> bool:
        return (
            state.recording == self.recording
            and self.views <= state.views
            and all(state.timeline_max.get(k) == v for k, v in self.timeline_max.items())
        )


def expected_state(rrd: Path) -> Expected:
    """The recording id, the blueprint's view names and the sequence timelines' last values of ``rrd``."""
    from rerun.chunk import RrdReader

    reader = RrdReader(rrd)
    (entry,) = reader.recordings()
    views: set[str] = set()
    for blueprint in reader.blueprints():
        for chunk in reader.stream(store=blueprint):
            for row in (
                chunk.to_record_batch()
                .select([n for n in chunk.to_record_batch().schema.names if n == "ViewBlueprint:display_name"])
                .to_pylist()
            ):
                if row.get("ViewBlueprint:display_name"):
                    views.add(row["ViewBlueprint:display_name"][0])
    maxima: dict[str, int] = {}
    for chunk in reader.store().stream():
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        for name in ("frame", "focus"):
            if name in batch.schema.names and batch.num_rows:
                top = max(v for v in batch.column(name).to_pylist() if v is not None)
                maxima[name] = max(maxima.get(name, top), top)
    return Expected(f"Recording:{entry.application_id}:{entry.recording_id}", frozenset(views), maxima)


class WebCheckError(RuntimeError):
    """The browser check could not run (a server did not start, the page never rendered)."""


@dataclass(frozen=True, slots=True)
class RegionStats:
    """Pixels of one screenshot region (x0, y0, x1, y1): the fraction that differs from the region's
    background colour, the number of distinct colours among them, and the fraction of coloured (non-grey)
    pixels."""

    box: tuple[int, int, int, int]
    foreground_fraction: float
    distinct_colors: int
    colored_fraction: float

    @property
    def rendered(self) -> bool:
        return (
            self.foreground_fraction >= MIN_FOREGROUND_FRACTION
            and self.distinct_colors >= MIN_DISTINCT_COLORS
            and self.colored_fraction >= MIN_COLORED_FRACTION
        )


@dataclass(frozen=True, slots=True)
class WebCheckResult:
    """Outcome of ``check_recording``: the screenshot written; whether it is ready (the viewer's state shows everything
    loaded, no backlog, every 3D-view region rendered); seconds from navigation until the viewer's state showed
    everything loaded, to the first full-size shot with rendered views (taken once the small views rendered, unless
    ``loading_viewport`` is None) and to the ready shot (None if never); shots taken; total wall time; the last shot's
    region stats; the server and browser process groups; the viewer's last state; the CPU seconds Chromium's processes
    (browser, renderer, GPU: the software WebGL) and the web-viewer server used, read just before they were stopped
    (``group_cpu_s``)."""

    screenshot: Path
    rendered: bool
    seconds_to_load: float | None
    seconds_to_render: float | None
    seconds_to_settle: float | None
    shots: int
    total_s: float
    regions: tuple[RegionStats, ...]
    process_groups: tuple[int, ...]
    state: ViewerState
    browser_cpu_s: float
    server_cpu_s: float

    def describe(self) -> str:
        parts = ", ".join(
            f"{r.foreground_fraction:.1%} foreground, {r.distinct_colors} colours, {r.colored_fraction:.2%} coloured"
            for r in self.regions
        )
        if self.rendered:
            when = (
                f"loaded (viewer state) after {self.seconds_to_load:.1f} s, rendered after "
                f"{self.seconds_to_render:.1f} s, ready after {self.seconds_to_settle:.1f} s"
            )
        else:
            when = f"NOT ready (loaded: {self.seconds_to_load})"
        cpu = f"CPU: Chromium {self.browser_cpu_s:.1f} s, web-viewer server {self.server_cpu_s:.1f} s"
        return f"{when} ({self.shots} shots, {self.total_s:.1f} s in all; {cpu}); 3D views: {parts}; {self.screenshot}"


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def rerun_executable() -> Path:
    """The ``rerun`` CLI installed next to this Python interpreter (the venv's)."""
    exe = Path(sys.executable).parent / "rerun"
    if not exe.is_file():
        raise WebCheckError(f"the rerun CLI is not installed next to {sys.executable}")
    return exe


class _QuietCorsHandler(http.server.SimpleHTTPRequestHandler):
    """Files of one folder, readable from the web viewer's page on another port (CORS), without a log line per
    request."""

    def end_headers(self) -> None:
        self.send_header("Access-Control-Allow-Origin", "*")
        super().end_headers()

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 (the base class's name)
        pass


@contextlib.contextmanager
def served_file(path: Path) -> Iterator[str]:
    """The URL of ``path`` served over HTTP on 127.0.0.1 (a free port) by a thread of this process, for as long
    as the context lasts."""
    handler = functools.partial(_QuietCorsHandler, directory=str(path.parent))
    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler) as httpd:
        thread = threading.Thread(target=httpd.serve_forever, name="webcheck-file", daemon=True)
        thread.start()
        try:
            yield f"http://127.0.0.1:{httpd.server_address[1]}/{urllib.parse.quote(path.name)}"
        finally:
            httpd.shutdown()
            thread.join()


@contextlib.contextmanager
def process_group(
    argv: Sequence[str], log_path: Path, grace_s: float = 5.0, env: Mapping[str, str] | None = None
) -> Iterator[subprocess.Popen[bytes]]:
    """Run ``argv`` in a new session (its own process group) with ``env`` (default: this process's), output to
    ``log_path``; on exit SIGTERM the whole group, then SIGKILL whatever is left after ``grace_s``, and reap the
    leader."""
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            list(argv),
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
            env=None if env is None else dict(env),
        )
    try:
        yield proc
    finally:
        _kill_group(proc, grace_s)


def _kill_group(proc: subprocess.Popen[bytes], grace_s: float) -> None:
    """SIGTERM the process group led by ``proc``, SIGKILL it if anything is still running ``grace_s`` later,
    and reap the leader."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, sig)
        deadline = time.monotonic() + grace_s
        while group_members(proc.pid) and time.monotonic() < deadline:
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(timeout=0.1)
        if not group_members(proc.pid):
            break
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=5.0)


def _running_in_group(pgid: int) -> Iterator[tuple[int, list[str]]]:
    """(pid, the fields of ``/proc/PID/stat`` after the command name) of each running (not zombie) process in
    process group ``pgid``."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # the process ended while we looked
        if int(fields[2]) == pgid and fields[0] not in ("Z", "X"):
            yield int(stat.parent.name), fields


def group_members(pgid: int) -> list[int]:
    """Pids of the running (not zombie) processes in process group ``pgid``, from ``/proc``."""
    return [pid for pid, _ in _running_in_group(pgid)]


def group_cpu_s(pgid: int) -> float:
    """CPU seconds (user + system) used so far by the running processes of group ``pgid`` and by the children
    they have reaped, from ``/proc`` (a process that left the group, or ended unreaped by it, is not counted)."""
    ticks = sum(sum(int(f) for f in fields[11:15]) for _, fields in _running_in_group(pgid))  # u, s, cu, cs time
    return ticks / os.sysconf("SC_CLK_TCK")


def _wait_for_http(url: str, timeout_s: float, proc: subprocess.Popen[bytes], what: str, log: Path) -> bytes:
    """GET ``url`` until it answers (returns the body); fail early if ``proc`` died."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with urllib.request.urlopen(url, timeout=2.0) as response:
                return response.read()
        except (urllib.error.URLError, ConnectionError, TimeoutError, OSError):
            pass
        if proc.poll() is not None:
            raise WebCheckError(f"{what} exited with code {proc.returncode}; see {log}")
        if time.monotonic() > deadline:
            raise WebCheckError(f"{what} did not answer at {url} within {timeout_s:.0f} s; see {log}")
        time.sleep(0.25)


class DevToolsBusy(WebCheckError):
    """The page did not answer a DevTools command in time (its thread busy rendering); ask again later."""


class DevTools:
    """A minimal Chrome DevTools protocol client over one page's websocket: ``call`` sends a command and waits
    for its reply (events in between are ignored). A reply can take minutes: software WebGL on a busy 2-core
    machine holds the page's thread that long while the recording streams in, so a poll without a reply in
    ``timeout_s`` is skipped (``DevToolsBusy``) rather than fatal."""

    def __init__(self, ws_url: str, timeout_s: float = 90.0) -> None:
        import websocket

        self._ws = websocket.create_connection(ws_url, timeout=timeout_s, suppress_origin=True)
        self._ids = itertools.count(1)

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """The reply to ``method``; DevToolsBusy when none came within the timeout (a later reply to it is
        skipped by the next call, which waits for its own id)."""
        import websocket

        msg_id = next(self._ids)
        self._ws.send(json.dumps({"id": msg_id, "method": method, "params": params}))
        while True:
            try:
                raw = self._ws.recv()
            except websocket.WebSocketTimeoutException:
                raise DevToolsBusy(f"DevTools {method}: no reply yet") from None
            reply = json.loads(raw)
            if reply.get("id") != msg_id:
                continue
            if "error" in reply:
                raise WebCheckError(f"DevTools {method} failed: {reply['error'].get('message', reply['error'])}")
            return reply.get("result", {})

    def close(self) -> None:
        self._ws.close()


def runs_side_by_side(rrd: Path) -> int:
    """How many runs' bird's-eye views the recording's default blueprint lays side by side (at least 1): the
    ``view_regions`` to check. A fixed 2 checked the right half of a one-run recording's bird's-eye view as a
    second view; on the dev set (no LiDAR) that half is often bare ground with a box or two, never "rendered", and
    the check waited out its whole timeout and said NOT ready (dev set scene-0103 cphd ``--focus
    identity_theft:1``: 424 s, exit 1, for a view that had rendered in 40 s)."""
    from tools.labels import read_views

    return max(1, sum(v.name.endswith("bird's-eye") for v in read_views(rrd, kinds=("3D",))))


def view_regions(width: int, height: int, n_views: int) -> list[tuple[int, int, int, int]]:
    """(x0, y0, x1, y1) pixel boxes well inside the bird's-eye view of each of the ``n_views`` trackers side by
    side in the default blueprint (``viz.blueprint``): they span the left three fifths of the window, in the
    top part of each tracker's column; each box keeps clear of view borders, titles and the top bar."""
    left, right = 0.0, 0.6 * width
    top, bottom = 0.08 * height, 0.40 * height
    step = (right - left) / n_views
    boxes = []
    for i in range(n_views):
        x0 = left + i * step
        boxes.append((int(x0 + 0.1 * step), int(top), int(x0 + 0.9 * step), int(bottom)))
    return boxes


def region_stats(image: np.ndarray, box: tuple[int, int, int, int]) -> RegionStats:
    """Foreground fraction, distinct colours and coloured fraction of an (H, W, 3) uint8 image inside ``box``;
    the background is the region's most common colour."""
    x0, y0, x1, y1 = box
    pixels = np.ascontiguousarray(image[y0:y1, x0:x1, :3]).reshape(-1, 3)
    if pixels.size == 0:
        return RegionStats(box, 0.0, 0, 0.0)
    packed = (pixels[:, 0].astype(np.uint32) << 16) | (pixels[:, 1].astype(np.uint32) << 8) | pixels[:, 2]
    colors, counts = np.unique(packed, return_counts=True)
    mode = colors[np.argmax(counts)]
    background = np.array([(mode >> 16) & 255, (mode >> 8) & 255, mode & 255], dtype=np.int16)
    foreground = np.any(np.abs(pixels.astype(np.int16) - background) > BACKGROUND_TOLERANCE, axis=1)
    distinct = int(np.unique(packed[foreground]).size)
    spread = pixels.max(axis=1).astype(np.int16) - pixels.min(axis=1)
    return RegionStats(box, float(foreground.mean()), distinct, float(np.mean(spread > SATURATION_MIN)))


def backlog_region(width: int) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) of the top-bar text where the viewer reports its ingestion backlog (left of the
    centred command search box)."""
    return STATUS_X[0], STATUS_Y[0], min(STATUS_X[1], width // 2 - 220), STATUS_Y[1]


def backlog_shown(image: np.ndarray) -> bool:
    """Whether the viewer's top bar shows an ingestion backlog (text in ``backlog_region``)."""
    return region_stats(image, backlog_region(image.shape[1])).foreground_fraction > 0.005


def decode_png(data: bytes) -> np.ndarray:
    """(H, W, 3) uint8 RGB pixels of a PNG."""
    from PIL import Image

    with Image.open(io.BytesIO(data)) as img:
        return np.asarray(img.convert("RGB"))


def _page_websocket(debug_port: int, proc: subprocess.Popen[bytes], log: Path, timeout_s: float) -> str:
    deadline = time.monotonic() + timeout_s
    while True:
        body = _wait_for_http(f"http://127.0.0.1:{debug_port}/json/list", timeout_s, proc, "chromium", log)
        pages = [t for t in json.loads(body) if t.get("type") == "page" and t.get("webSocketDebuggerUrl")]
        if pages:
            return str(pages[0]["webSocketDebuggerUrl"])
        if time.monotonic() > deadline:
            raise WebCheckError(f"chromium opened no page within {timeout_s:.0f} s; see {log}")
        time.sleep(0.25)


@dataclass(frozen=True, slots=True)
class Chromium:
    """A running headless Chromium (``proc`` leads its process group) and the DevTools client of its one page,
    whose viewport is ``viewport``."""

    proc: subprocess.Popen[bytes]
    devtools: DevTools
    viewport: tuple[int, int]


@contextlib.contextmanager
def headless_chromium(
    work: Path, viewport: tuple[int, int] = DEFAULT_VIEWPORT, chromium: Path = CHROMIUM
) -> Iterator[Chromium]:
    """Headless Chromium with a fresh profile and its temporary folders under ``work`` (its log there too), its
    page sized ``viewport``; its whole process group is killed on exit. Several recordings checked in one browser
    share its GPU process, where software WebGL compiles the web viewer's shaders once."""
    if not chromium.is_file():
        raise WebCheckError(f"chromium is not installed at {chromium}")
    width, height = viewport
    debug_port, log = free_port(), work / "chromium.log"
    argv = [str(chromium), *CHROMIUM_FLAGS, f"--remote-debugging-port={debug_port}"]
    argv += [f"--user-data-dir={work / 'chromium-profile'}", f"--window-size={width},{height}", "about:blank"]
    # TMPDIR: Chromium's own temporary folders (org.chromium.Chromium.*, left in /tmp when it is killed) go
    # under ``work`` too
    with process_group(argv, log, env={**os.environ, "TMPDIR": str(work)}) as proc:
        devtools = DevTools(_page_websocket(debug_port, proc, log, 60.0))
        try:
            devtools.call(
                "Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False
            )
            yield Chromium(proc, devtools, viewport)
        finally:
            devtools.close()


def check_recording(
    rrd: Path,
    out: Path,
    *,
    n_views: int = 2,
    viewport: tuple[int, int] = DEFAULT_VIEWPORT,
    timeout_s: float = 420.0,
    poll_s: float = 1.0,
    settle_poll_s: float = 1.5,
    chromium: Path = CHROMIUM,
    work_dir: Path | None = None,
    browser: Chromium | None = None,
    loading_viewport: tuple[int, int] | None = LOADING_VIEWPORT,
) -> WebCheckResult:
    """Serve ``rrd`` with Rerun's web viewer, open it in headless Chromium and write a PNG screenshot to
    ``out``.

    The page is ``loading_viewport`` in size (the browser's full viewport if None) until the viewer's state,
    read every ``poll_s`` seconds (a read costs next to nothing; every 1 s rather than 4 s saw the load 2-4 s
    sooner, and Chromium's CPU for both recordings was 47 and 44 s against 48 and 53 s), shows everything
    loaded and a shot of it (one every ``settle_poll_s`` seconds) shows every view region rendered; then it is
    the full viewport and a screenshot is taken every ``settle_poll_s`` seconds (the viewer idles then: a shot
    costs little, waiting costs the worker),
    until every one of the ``n_views`` 3D-view regions (``view_regions``) looks rendered and the page has settled
    (SETTLED_SHOTS shots in a row without an ingestion backlog), or ``timeout_s`` passes; ``out`` holds the last
    shot either way (so a failure can be looked at). Server logs and the browser profile go to ``work_dir`` (a
    temp dir if None). Raises WebCheckError when a server does not start.
    """
    rrd, out = Path(rrd).absolute(), Path(out).absolute()
    if not rrd.is_file():
        raise WebCheckError(f"recording {rrd} does not exist")
    expected = expected_state(rrd)
    start = time.monotonic()
    own_browser = browser is None
    with contextlib.ExitStack() as stack:
        work = Path(work_dir) if work_dir is not None else Path(stack.enter_context(tempfile.TemporaryDirectory()))
        work.mkdir(parents=True, exist_ok=True)
        web_port = free_port()
        serve_log = work / f"rerun-serve-{rrd.stem}.log"
        rrd_url = stack.enter_context(served_file(rrd))
        server = stack.enter_context(
            process_group(
                [str(rerun_executable()), rrd_url, "--serve-web", "--web-viewer-port", str(web_port)]
                + ["--bind", "127.0.0.1"],
                serve_log,
            )
        )
        _wait_for_http(f"http://127.0.0.1:{web_port}/", 60.0, server, "rerun --serve-web", serve_log)
        if browser is None:
            browser = stack.enter_context(headless_chromium(work, viewport, chromium))
        width, height = browser.viewport
        devtools = browser.devtools
        cpu_before_s = group_cpu_s(browser.proc.pid)
        url = f"http://127.0.0.1:{web_port}/?url={urllib.parse.quote(rrd_url, safe='')}"
        if loading_viewport is not None:
            _set_viewport(devtools, loading_viewport)
        devtools.call("Page.navigate", url=url)
        navigated = time.monotonic()
        boxes = view_regions(width, height, n_views)
        shots, settled = 0, 0
        small = loading_viewport is not None
        first_rendered: float | None = None
        loaded: float | None = None
        stats: tuple[RegionStats, ...] = ()
        state = ViewerState(None, frozenset(), {})
        while True:
            time.sleep(poll_s if loaded is None else settle_poll_s)
            elapsed = time.monotonic() - navigated
            try:
                raw = devtools.call("Runtime.evaluate", expression=VIEWER_STATE_JS, returnByValue=True)
                value = raw.get("result", {}).get("value")
                if value:
                    state = read_viewer_state(base64.b64decode(value))
                    if loaded is None and expected.met_by(state):
                        loaded = elapsed
                if loaded is None and small and elapsed <= timeout_s:
                    continue
                png = base64.b64decode(devtools.call("Page.captureScreenshot", format="png")["data"])
            except DevToolsBusy:
                if elapsed > timeout_s:
                    break
                continue
            if small:
                shots += 1
                image = decode_png(png)
                small_boxes = view_regions(image.shape[1], image.shape[0], n_views)
                rendered_small = all(region_stats(image, b).rendered for b in small_boxes)
                if rendered_small or elapsed > min(timeout_s, (loaded or 0.0) + SMALL_RENDER_WAIT_S):
                    _set_viewport(devtools, (width, height))
                    small = False
                continue
            shots += 1
            write_bytes(out, png)
            image = decode_png(png)
            stats = tuple(region_stats(image, b) for b in boxes)
            if all(s.rendered for s in stats):
                first_rendered = elapsed if first_rendered is None else first_rendered
                settled = settled + 1 if loaded is not None and not backlog_shown(image) else 0
            else:
                first_rendered, settled = None, 0
            if settled >= SETTLED_SHOTS or elapsed > timeout_s:
                break
            if server.poll() is not None:
                raise WebCheckError(f"rerun --serve-web exited with code {server.returncode}; see {serve_log}")
        browser_cpu_s, server_cpu_s = group_cpu_s(browser.proc.pid) - cpu_before_s, group_cpu_s(server.pid)
    done = settled >= SETTLED_SHOTS
    return WebCheckResult(
        out,
        done,
        loaded,
        first_rendered if done else None,
        elapsed if done else None,
        shots,
        time.monotonic() - start,
        stats,
        (server.pid, browser.proc.pid) if own_browser else (server.pid,),
        state,
        browser_cpu_s,
        server_cpu_s,
    )


def _set_viewport(devtools: DevTools, viewport: tuple[int, int]) -> None:
    width, height = viewport
    devtools.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tools.webcheck",
        description="Open a saved .rrd in Rerun's web viewer in headless Chromium; screenshot its 3D views.",
    )
    parser.add_argument("rrd", type=Path, help="the recording (.rrd)")
    parser.add_argument("--out", type=Path, default=Path("webcheck.png"), help="screenshot to write (PNG)")
    parser.add_argument(
        "--views",
        type=int,
        default=None,
        help="number of side-by-side 3D views to check (default: the runs the recording's blueprint lays side by side)",
    )
    parser.add_argument("--timeout", type=float, default=420.0, help="seconds to wait for the scene to render")
    parser.add_argument("--width", type=int, default=DEFAULT_VIEWPORT[0])
    parser.add_argument("--height", type=int, default=DEFAULT_VIEWPORT[1])
    args = parser.parse_args(argv)
    try:
        result = check_recording(
            args.rrd,
            args.out,
            n_views=args.views if args.views is not None else runs_side_by_side(args.rrd),
            viewport=(args.width, args.height),
            timeout_s=args.timeout,
        )
    except WebCheckError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(result.describe())
    return 0 if result.rendered else 1


if __name__ == "__main__":
    sys.exit(main())
