"""Struct-of-arrays dataclasses: every field is an array (or another struct-of-arrays) indexed by item.

Boxes, Bernoullis, Gaussian mixtures and vector tracks keep one array per attribute so trackers vectorise over
items; selecting and joining items is the same for all of them and lives here.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from typing import Any, Self

import numpy as np


class StructOfArrays:
    """Mixin for a dataclass whose fields all have the item count as first dimension. Subclasses provide
    ``empty()`` (zero items with the right shapes and dtypes)."""

    __slots__ = ()

    def __len__(self) -> int:
        return len(getattr(self, _field_names(type(self))[0]))

    @classmethod
    def empty(cls) -> Self:
        raise NotImplementedError(f"{cls.__name__} must define empty()")

    def subset(self, index: Any) -> Self:
        """The items selected by an integer or boolean index, in that order."""
        return type(self)(**{name: _take(getattr(self, name), index) for name in _field_names(type(self))})

    @classmethod
    def concatenate(cls, parts: Sequence[Self]) -> Self:
        """The items of ``parts`` in order (parts without items are skipped)."""
        parts = [p for p in parts if len(p)]
        if not parts:
            return cls.empty()
        if len(parts) == 1:
            return parts[0]
        return cls(**{name: _join([getattr(p, name) for p in parts]) for name in _field_names(cls)})


@functools.cache
def _field_names(cls: type) -> tuple[str, ...]:
    """The dataclass field names of ``cls``, in order (``dataclasses.fields`` rebuilds this tuple on every call,
    which showed in PMBM's profile: thousands of subsets per frame)."""
    return tuple(f.name for f in dataclasses.fields(cls))


def _take(value: Any, index: Any) -> Any:
    return value.subset(index) if isinstance(value, StructOfArrays) else value[index]


def _join(values: list[Any]) -> Any:
    if isinstance(values[0], StructOfArrays):
        return type(values[0]).concatenate(values)
    return np.concatenate(values)
