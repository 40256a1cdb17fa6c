"""Derived values live on the immutable object they derive from; no module holds state."""

from __future__ import annotations

import ast
import pickle

from tests.conftest import REPO
from trackplan.derived import STORE, derived
from trackplan.robots.builtin import puma560
from trackplan.robots.families import ik_family


def test_a_derived_value_is_built_once_per_owner_and_key():
    robot = puma560()
    calls: list[int] = []

    def build() -> list[int]:
        calls.append(1)
        return [len(calls)]

    first = derived(robot, "probe", build)
    assert derived(robot, "probe", build) is first and calls == [1]
    assert derived(robot, ("probe", 2), build) == [2]  # another key: built again
    assert derived(puma560(), "probe", build) == [3]  # another owner: its own store


def test_the_store_pickles_empty_and_is_rebuilt_in_the_receiver():
    robot = puma560()
    family = ik_family(robot)
    assert getattr(robot, STORE)  # the family is kept on the robot
    received = pickle.loads(pickle.dumps(robot))
    assert not getattr(received, STORE, {})  # nothing derived travels with it
    assert type(ik_family(received)) is type(family)


def _module_state(tree: ast.Module) -> list[str]:
    """Names bound at module level to a weak-keyed cache."""
    found = []
    for node in tree.body:
        value = node.value if isinstance(node, ast.Assign | ast.AnnAssign) else None
        if isinstance(value, ast.Call) and "WeakKeyDictionary" in ast.unparse(value.func):
            found.append(ast.unparse(node).split("=")[0].strip())
    return found


def test_no_module_keeps_a_cache_of_objects():
    planted = ast.parse("import weakref\n_SEEN = weakref.WeakKeyDictionary()\n")
    assert _module_state(planted) == ["_SEEN"]
    found = {
        str(file.relative_to(REPO)): names
        for file in (REPO / "trackplan").rglob("*.py")
        if (names := _module_state(ast.parse(file.read_text(encoding="utf-8"))))
    }
    assert found == {}
