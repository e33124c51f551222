"""Provenance in a Rerun recording: sent as a static recording property, read back from a saved ``.rrd``.

Rerun 0.41 stores a property ``name`` as static components of the entity ``/__properties/<name>`` (the viewer
lists them with the recording). The property ``provenance`` holds the canonical JSON of a
``gnnpmb.provenance.Provenance`` (component ``json``, the one that is read back) and readable copies of its
main fields (command, versions, data source, detections, seed, frames, classes, trackers, track digests).
"""

from __future__ import annotations

import shlex
import warnings
from pathlib import Path

import rerun as rr

from gnnpmb.errors import DataError
from gnnpmb.provenance import Provenance
from gnnpmb.symlinks import refuse_symlink_loop

PROPERTY = "provenance"
PROPERTY_ENTITY = f"/__properties/{PROPERTY}"
JSON_COMPONENT = "json"


def log_provenance(stream: rr.RecordingStream, provenance: Provenance) -> None:
    """Send ``provenance`` as the static property ``provenance`` of the recording (replacing an earlier
    one)."""
    p = provenance
    stream.send_property(
        PROPERTY,
        rr.AnyValues(
            **{
                JSON_COMPONENT: p.dumps(),
                "command": shlex.join(p.argv),
                "versions": ", ".join(f"{k} {v}" for k, v in p.versions.items()),
                "data_source": f"{p.data_source} at {p.dataroot}",
                "scene": f"{p.scene_name} (token {p.scene_token})",
                "detections": p.detections.describe(),
                "seed": str(p.seed),
                "frames": f"{p.frame_start}:{p.frame_end}",
                "classes": ",".join(p.classes),
                "trackers": ", ".join(p.trackers),
                "track_digests": ", ".join(f"{t} {d.overall[:16]}" for t, d in p.track_digests.items()),
            }
        ),
    )


def read_provenance(path: Path) -> Provenance:
    """The provenance stored in the saved recording ``path``; a DataError says why there is none."""
    from rerun.chunk import RrdReader
    from rerun.error_utils import RerunWarning

    path = Path(path)
    refuse_symlink_loop(path, "recording")
    if not path.is_file():
        raise DataError(f"recording {path} does not exist")
    try:
        with warnings.catch_warnings():  # e.g. "no footer" before the error of a truncated file
            warnings.simplefilter("ignore", RerunWarning)
            store = RrdReader(path).store()
        chunks = store.stream().filter(content=PROPERTY_ENTITY, is_static=True)
        texts = [
            value
            for chunk in chunks
            if chunk.entity_path == PROPERTY_ENTITY
            for row in chunk.to_record_batch().to_pylist()
            for value in (row.get(JSON_COMPONENT) or [])
        ]
    except (OSError, ValueError, RuntimeError) as exc:
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise DataError(f"{path} is not a readable Rerun recording ({detail})") from None
    if not texts:
        raise DataError(
            f"{path} has no gnnpmb-viz provenance; only recordings saved by "
            "'gnnpmb-viz SCENE --save FILE.rrd' can be reproduced"
        )
    return Provenance.loads(texts[-1])
