"""Where gnnpmb-viz keeps what it can make again (the demo dataset, dataset indexes, evaluation subsets, failure
reports): ``$GNNPMB_CACHE_DIR``, else the user cache folder of gnnpmb-viz."""

from __future__ import annotations

import os
from pathlib import Path

CACHE_ENV = "GNNPMB_CACHE_DIR"


def cache_root() -> Path:
    """gnnpmb-viz's cache folder: ``$GNNPMB_CACHE_DIR`` or the user cache dir of gnnpmb-viz."""
    root = os.environ.get(CACHE_ENV)
    if not root:
        import platformdirs

        root = platformdirs.user_cache_dir("gnnpmb-viz")
    return Path(root).expanduser()
