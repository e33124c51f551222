"""Read one large JSON object member by member with bounded memory: the ``results`` of a detection file, the rows
of a nuScenes table.

Why not a streaming-parser library: ijson (yajl) rejects ``NaN``, which Python's ``json.dump`` writes for the
unknown velocities the devkit allows in detection files; json-stream parses in pure Python (minutes for 500 MB).
So the text is read in blocks and each member is decoded by the standard library's own C decoder
(``json.JSONDecoder.raw_decode``), from where the previous one ended: the values are exactly what ``json.loads``
of the whole file gives, while only the current block and one member are in memory. A member cut by the end of
a block is decoded again once the next block is read; a member larger than ``MAX_MEMBER_CHARS`` is an error.
Malformed or truncated text raises ``JsonStreamError`` with the line and column in the whole file.
"""

from __future__ import annotations

import codecs
import json
from collections.abc import Callable, Iterator
from typing import IO, Any

BLOCK_BYTES = 1 << 22
"""Bytes read at a time (4 MiB)."""
MAX_MEMBER_CHARS = 1 << 26
"""The largest single member (a sample's boxes, a table row) accepted: 64 Mi characters."""
_WS = " \t\n\r"
_NUMBER_CHARS = frozenset("0123456789+-.eE")
_DECODER = json.JSONDecoder()


class JsonStreamError(Exception):
    """Malformed JSON text: what the decoder said and where (1-based line and column, 0-based character)."""

    def __init__(self, msg: str, line: int, column: int, char: int) -> None:
        super().__init__(f"{msg} at line {line}, column {column} (character {char})")
        self.msg, self.line, self.column, self.char = msg, line, column, char


class NotUtf8Error(Exception):
    """The file is not UTF-8 text; ``byte`` is the offset of the first bad byte."""

    def __init__(self, byte: int) -> None:
        super().__init__(f"bad byte at position {byte}")
        self.byte = byte


class _Text:
    """The file's text as a sliding window: ``buf`` holds the text from character ``base`` on, ``pos`` is the
    reading position in ``buf``; the lines before ``buf`` are counted for error messages."""

    def __init__(self, f: IO[bytes], on_bytes: Callable[[bytes], None]) -> None:
        self.f = f
        self.on_bytes = on_bytes
        self.decoder = codecs.getincrementaldecoder("utf-8")()
        self.buf = ""
        self.pos = 0
        self.base = 0
        self.lines_before = 0
        self.line_start = 0
        self.bytes_read = 0
        self.eof = False

    def more(self) -> bool:
        """Append the next block (first forgetting the text already read); False at the end of the file."""
        if self.eof:
            return False
        self._forget()
        block = self.f.read(BLOCK_BYTES)
        self.on_bytes(block)
        try:
            text = self.decoder.decode(block, final=not block)
        except UnicodeDecodeError as exc:
            raise NotUtf8Error(self.bytes_read + exc.start) from None
        self.bytes_read += len(block)
        self.eof = not block
        self.buf += text
        return True

    def _forget(self) -> None:
        """Drop the text before ``pos``."""
        dropped = self.buf[: self.pos]
        newlines = dropped.count("\n")
        if newlines:
            self.lines_before += newlines
            self.line_start = self.base + dropped.rindex("\n") + 1
        self.base += self.pos
        self.buf = self.buf[self.pos :]
        self.pos = 0

    def error(self, msg: str, at: int) -> JsonStreamError:
        before = self.buf[:at]
        newlines = before.count("\n")
        line_start = self.base + before.rindex("\n") + 1 if newlines else self.line_start
        char = self.base + at
        return JsonStreamError(msg, self.lines_before + newlines + 1, char - line_start + 1, char)

    def peek(self) -> str:
        """The next non-blank character ("" at the end of the file), without consuming it."""
        while True:
            while self.pos < len(self.buf) and self.buf[self.pos] in _WS:
                self.pos += 1
            if self.pos < len(self.buf):
                return self.buf[self.pos]
            if not self.more():
                return ""

    def expect(self, chars: str, what: str) -> str:
        """Consume the next non-blank character, which must be one of ``chars``."""
        c = self.peek()
        if not c or c not in chars:
            raise self.error(f"Expecting {what}", self.pos)
        self.pos += 1
        return c

    def value(self) -> Any:
        """Decode the next JSON value, reading on while it is cut by the block end."""
        self.peek()
        while True:
            try:
                value, end = _DECODER.raw_decode(self.buf, self.pos)
            except json.JSONDecodeError as exc:
                if len(self.buf) - self.pos < MAX_MEMBER_CHARS and self.more():
                    continue
                raise self.error(exc.msg, exc.pos) from None
            if self._ends_inside(value, end) and self.more():
                continue  # a number cut by the block end decodes short ("1.5e" as 1.5): read on
            self.pos = end
            return value

    def _ends_inside(self, value: Any, end: int) -> bool:
        """Whether a decoded number may go on past the text read so far (what is left of the buffer after it is
        at most the unread part of an exponent, e.g. "e+")."""
        if len(self.buf) - end > 2 or isinstance(value, dict | list | str):
            return False
        return all(c in _NUMBER_CHARS for c in self.buf[end:])


def iter_object(
    f: IO[bytes], on_bytes: Callable[[bytes], None] = lambda _b: None, member: str | None = None
) -> Iterator[tuple[str, Any]]:
    """(key, value) of each member of the top-level JSON object in ``f``, in file order, or with ``member`` of
    the object that is that top-level member's value (e.g. ``results``; other top-level members are decoded and
    skipped). ``on_bytes`` sees every block read (progress, hashing). Raises ``JsonStreamError``,
    ``NotUtf8Error``, ``KeyError(member)`` when the member is missing and ``TypeError(type name, member)`` when
    the top level (member None), or the member's value, is not an object."""
    text = _Text(f, on_bytes)
    _open(text, "{", None)
    if member is None:
        yield from _members(text)
        _end(text)
        return
    found = False
    for key in _keys(text):
        if key != member:
            text.value()
            continue
        _open(text, "{", member)
        found = True
        yield from _members(text)
    if not found:
        raise KeyError(member)
    _end(text)


def _open(text: _Text, bracket: str, member: str | None) -> None:
    """Consume the opening ``bracket`` of the next value (``TypeError`` naming what is there instead)."""
    c = text.peek()
    if not c:
        raise text.error("Expecting value", text.pos)
    if c != bracket:
        raise TypeError(type(text.value()).__name__, member)
    text.pos += 1


def _end(text: _Text) -> None:
    """Only blanks may follow the top-level value."""
    if text.peek():
        raise text.error("Extra data", text.pos)


def _keys(text: _Text) -> Iterator[str]:
    """Each member's key of the object just opened; the caller consumes the value after each."""
    if text.peek() == "}":
        text.pos += 1
        return
    while True:
        if text.peek() != '"':
            raise text.error("Expecting property name enclosed in double quotes", text.pos)
        key = text.value()
        text.expect(":", "':' delimiter")
        yield key
        if text.expect(",}", "',' delimiter") == "}":
            return


def _members(text: _Text) -> Iterator[tuple[str, Any]]:
    for key in _keys(text):
        yield key, text.value()


def iter_array(f: IO[bytes], on_bytes: Callable[[bytes], None] = lambda _b: None) -> Iterator[Any]:
    """Each item of the top-level JSON array in ``f`` (a nuScenes table), in order. Raises ``JsonStreamError``,
    ``NotUtf8Error`` and ``TypeError(type name, None)`` when the top level is not an array."""
    text = _Text(f, on_bytes)
    _open(text, "[", None)
    if text.peek() == "]":
        text.pos += 1
        _end(text)
        return
    while True:
        yield text.value()
        if text.expect(",]", "',' delimiter") == "]":
            _end(text)
            return
