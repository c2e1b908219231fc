"""Backend configs filled from mission sections by field name (pfctl.app.sections)."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import pytest

from pfctl.app.sections import from_section


@dataclass(frozen=True)
class _Leg:
    name: str
    length: float


@dataclass(frozen=True)
class _Trip:
    speed: float
    first: _Leg
    legs: tuple[_Leg, ...]
    note: str


def test_fields_come_by_name_nested_and_in_tuples_and_given_ones_win() -> None:
    leg = SimpleNamespace(name="a", length=2.0, colour="red")  # extra attributes are left
    section = SimpleNamespace(
        speed=0.8, first=leg, legs=(leg, SimpleNamespace(name="b", length=1.5))
    )
    trip = from_section(_Trip, section, note="given")
    assert trip == _Trip(0.8, _Leg("a", 2.0), (_Leg("a", 2.0), _Leg("b", 1.5)), "given")


def test_a_field_the_section_lacks_is_an_error() -> None:
    leg = SimpleNamespace(name="a", length=1.0)
    with pytest.raises(AttributeError, match="note"):
        from_section(_Trip, SimpleNamespace(speed=1.0, first=leg, legs=()))
