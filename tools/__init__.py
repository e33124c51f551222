"""Developer tools, run by hand from the repository root (``uv run python -m tools.<name>``); not shipped."""
