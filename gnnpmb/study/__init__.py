"""Parameter studies scored with the official evaluation: grids (``sweep``), searches (``tune``) and parallel
tracking (``track --workers``), run in this process or on Ray."""
