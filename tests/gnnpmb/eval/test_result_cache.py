"""A cached row damaged in place (a digit changed: still JSON) counts as not cached."""

from __future__ import annotations

from pathlib import Path

from gnnpmb.eval.result_cache import ResultCache


def test_a_row_edited_in_place_is_not_served(tmp_path: Path) -> None:
    cache = ResultCache(tmp_path)
    cache.put("k", {"amota": 0.512, "ids": 7, "name": None})
    assert cache.get("k") == {"amota": 0.512, "ids": 7, "name": None}
    path = tmp_path / "k.json"
    path.write_text(path.read_text().replace("0.512", "0.912"))
    assert cache.get("k") is None
    path.write_text('{"amota": 0.5}')  # a file of the old layout: scored again
    assert cache.get("k") is None
    assert cache.get("missing") is None
