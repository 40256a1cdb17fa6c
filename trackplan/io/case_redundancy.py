"""The ``task.redundancy`` key of a case file: how a 7-joint arm's free parameter is steered."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator
from pydantic_core import PydanticCustomError

from trackplan.io.yaml_input import Coordinate, Range, StrictModel
from trackplan.redundancy.spec import DEFAULT_RATE, RedundancyMode, RedundancySpec

MAX_REDUNDANCY_RATE = 1e6
"""Largest ``task.redundancy.rate``, rad/m (the spin rate's bound)."""


class RedundancyModel(StrictModel):
    """``task.redundancy``: mode, value (rad), range (rad), rate (rad/m)."""

    mode: Literal["fixed", "free", "free-varying"] = "free-varying"
    value: Coordinate | None = None
    range: Range | None = None
    rate: Annotated[float, Field(gt=0, le=MAX_REDUNDANCY_RATE)] = DEFAULT_RATE

    @model_validator(mode="after")
    def _ordered(self) -> RedundancyModel:
        if self.range is not None and not self.range[0] < self.range[1]:
            raise PydanticCustomError(
                "redundancy_range", "range must be [min, max] with min < max (rad)"
            )
        return self


def as_redundancy(model: RedundancyModel | None) -> RedundancySpec:
    """The :class:`~trackplan.redundancy.RedundancySpec` of a ``task.redundancy`` (default
    when absent)."""
    if model is None:
        return RedundancySpec()
    return RedundancySpec(
        mode=RedundancyMode(model.mode),
        value=model.value,
        range=None if model.range is None else (float(model.range[0]), float(model.range[1])),
        rate=float(model.rate),
    )
