"""The block-wise JSON reader gives exactly what ``json.loads`` gives, and says where malformed text breaks."""

from __future__ import annotations

import io
import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gnnpmb.data import json_stream
from gnnpmb.data.json_stream import JsonStreamError, NotUtf8Error, iter_array, iter_object

_scalars = st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8)
_values = st.recursive(
    _scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=5), inner, max_size=4),
    max_leaves=20,
)


def _same(a: object, b: object) -> bool:
    """Equal, NaN equal to NaN, the same types (1 stays int, 1.0 float)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if type(a) is not type(b):
        return False
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    return a == b


@pytest.fixture(autouse=True)
def _tiny_blocks(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(json_stream, "BLOCK_BYTES", 5)  # every member is cut by block ends


@settings(max_examples=150, deadline=None)
@given(
    results=st.dictionaries(st.text(max_size=6), _values, max_size=6), meta=_values, indent=st.sampled_from([None, 1])
)
def test_members_equal_json_loads(results: dict, meta: object, indent: int | None) -> None:
    text = json.dumps({"meta": meta, "results": results, "tail": [1.5, "x"]}, indent=indent).encode()
    expected = json.loads(text)["results"]
    got = list(iter_object(io.BytesIO(text), member="results"))
    assert _same(dict(got), expected) and [k for k, _ in got] == list(expected)


@settings(max_examples=100, deadline=None)
@given(rows=st.lists(_values, max_size=8))
def test_array_items_equal_json_loads(rows: list) -> None:
    text = json.dumps(rows).encode()
    assert _same(list(iter_array(io.BytesIO(text))), json.loads(text))


def test_nan_and_unicode() -> None:
    text = '{"results": {"s\\u00e9": [{"velocity": [NaN, -Infinity]}, "\\u2603 é"]}}'.encode()
    ((key, value),) = list(iter_object(io.BytesIO(text), member="results"))
    assert key == "sé" and math.isnan(value[0]["velocity"][0]) and value[0]["velocity"][1] == -math.inf
    assert value[1] == "☃ é"


@pytest.mark.parametrize("cut", [0.3, 0.5, 0.9, 0.999])
def test_truncated_text_fails_where_json_loads_fails(cut: float) -> None:
    text = json.dumps({"results": {f"s{i}": [{"a": [i, 2.5], "b": "x"}] * 3 for i in range(5)}}, indent=1)
    part = text[: int(len(text) * cut)]
    with pytest.raises(JsonStreamError) as ours:
        list(iter_object(io.BytesIO(part.encode()), member="results"))
    with pytest.raises(json.JSONDecodeError) as theirs:
        json.loads(part)
    assert (ours.value.line, ours.value.column) == (theirs.value.lineno, theirs.value.colno)


def test_shapes_that_are_not_wanted() -> None:
    with pytest.raises(KeyError):
        list(iter_object(io.BytesIO(b'{"meta": {}}'), member="results"))
    with pytest.raises(TypeError) as info:
        list(iter_object(io.BytesIO(b'{"results": [1]}'), member="results"))
    assert info.value.args == ("list", "results")
    with pytest.raises(TypeError) as info:
        list(iter_object(io.BytesIO(b"[1]"), member="results"))
    assert info.value.args == ("list", None)
    with pytest.raises(JsonStreamError, match="Extra data"):
        list(iter_object(io.BytesIO(b'{"results": {}} x'), member="results"))
    with pytest.raises(NotUtf8Error) as bad:
        list(iter_array(io.BytesIO(b'["ok", "\xff"]')))
    assert bad.value.byte == 8
