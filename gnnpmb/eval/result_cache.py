"""Rows kept between runs: one JSON file per key (a hex SHA-256 the caller computes) in a folder, each written
atomically with the SHA-256 of its row, so a file damaged in place (a flipped digit still parses) counts as
absent, like a truncated one. The study's cache (``gnnpmb.study.cache``) and the failure reports
(``gnnpmb.eval.failure_cache``) keep their rows here.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gnnpmb.eval.submission import write_json


class ResultCache:
    """Finished rows keyed by a hex digest in ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)

    def _path(self, key: str) -> Path:
        return self.folder / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The stored row, or None if absent, unreadable or not matching its digest (a damaged file counts as not
        cached)."""
        try:
            data = json.loads(self._path(key).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        if not isinstance(data, dict) or not isinstance(data.get("row"), dict):
            return None
        return data["row"] if data.get("sha256") == _row_digest(data["row"]) else None

    def put(self, key: str, row: Mapping[str, Any]) -> None:
        write_json(self._path(key), {"sha256": _row_digest(row), "row": dict(row)})


def _row_digest(row: Mapping[str, Any]) -> str:
    """SHA-256 of a row's canonical JSON (sorted keys): the same for the row written and the row read back."""
    return hashlib.sha256(json.dumps(row, sort_keys=True, allow_nan=False).encode()).hexdigest()
