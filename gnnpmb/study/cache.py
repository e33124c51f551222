"""The resumable cache of a study: one JSON file per finished configuration under ``DIR/cache/``
(``gnnpmb.eval.result_cache.ResultCache``).

The file name is the SHA-256 of (tracker, the configuration's full parameter TOML, the inputs fingerprint, the
code version), so a configuration is rerun only if one of them changed. Files are written atomically, each with
the SHA-256 of its row: a file damaged in place (a flipped digit still parses) counts as not cached, like a
truncated one.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from typing import Any

CACHE_FOLDER = "cache"


def config_key(tracker: str, toml: Mapping[str, Any], inputs: str, code: str) -> str:
    """Cache key (hex SHA-256) of one configuration."""
    blob = {"tracker": tracker, "params": toml, "inputs": inputs, "code": code}
    return hashlib.sha256(json.dumps(blob, sort_keys=True, default=str).encode()).hexdigest()
