"""Values derived from an immutable object, computed once and kept with the object.

A robot's IK family and dynamics constants, a case's paths, a path's planning grid and
tool zones are pure functions of frozen inputs that many calls read. Each is kept in a
store on the object it derives from (:func:`derived`), so it lives and dies with that
object and no module holds state. The store pickles empty: a robot or a case sent to a
worker process recomputes what it needs there.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any, TypeVar

T = TypeVar("T")

STORE = "_derived"
"""The attribute of an object that holds its derived values."""


class DerivedStore(dict[Hashable, Any]):
    """The derived values of one object by key; it pickles (and copies deeply) empty."""

    def __reduce__(self) -> tuple[type[DerivedStore], tuple[()]]:
        return (DerivedStore, ())


def derived(owner: object, key: Hashable, build: Callable[[], T]) -> T:
    """``build()`` computed once per ``owner`` and ``key``, kept on ``owner``.

    Parameters
    ----------
    owner
        An immutable object with a ``__dict__`` (a frozen dataclass without slots); the
        value must depend on nothing but it (and the key).
    key
        What is derived (and any parameter it takes).
    build
        Computes the value.

    Returns
    -------
    The value, the same object at every call with this owner and key.
    """
    store = owner.__dict__.get(STORE)
    if store is None:
        store = owner.__dict__.setdefault(STORE, DerivedStore())
    if key not in store:
        store[key] = build()
    value: T = store[key]
    return value
