"""The number types of the case file's schema: finite floats and true integers (and q lists' range).

Every numeric key of the case file is one of these two, so ``softdesign
validate`` refuses what would otherwise reach the numeric core: NaN, inf and
``"1e400"`` (which reads as inf) for a float; a bool (``count: true`` is not
one link), a float (``count: 1e30``, ``count: 2.0``) or a string for an
integer; anything but true or false for a yes/no key (``enabled: "yes"``).
A float key takes an integer (``spacing_mm: 1``) and a number
written without a dot (YAML 1.1 reads ``1e-5`` as the string "1e-5"), but
never a bool.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AllowInfNan, BaseModel, BeforeValidator, ConfigDict, Strict


def _not_a_bool(value: Any) -> Any:
    if isinstance(value, bool):
        raise ValueError(f"must be a number, got {value!r} (true/false is not a number)")
    return value


#: A float that is finite (NaN, inf and overflowing strings like "1e400" are refused) and not a bool.
FiniteFloat = Annotated[float, BeforeValidator(_not_a_bool), AllowInfNan(False)]
#: An integer written as one: bools, floats and strings are refused.
Integer = Annotated[int, Strict()]
#: A yes/no key written as true or false: a string ("yes", "false", which would read as true) or a number is refused.
Flag = Annotated[bool, Strict()]


def q_in_range(values: list[float]) -> list[float]:
    """``values`` when each lies in [0, 1] (ValueError naming those that do not), for a list of q values."""
    bad = [v for v in values if not 0.0 <= v <= 1.0]
    if bad:
        raise ValueError(f"q values must lie in [0, 1], got {bad}")
    return values


class CaseBlock(BaseModel):
    """A block of the case file: unknown keys refused, frozen, each key's docstring its description.

    The docstrings become descriptions where they are read (the schema, the reference page), by
    :func:`softdesign.config.field_docs.attach_field_docs`, not at every start-up.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)
