"""A parameter declared once (pfctl.core.params): the field's default, and its meaning, unit and
bounds read back from the dataclass."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import pytest

from pfctl.core.params import ParamInfo, param, param_info
from pfctl.core.perception.tracking import TrackerParams


@dataclass(frozen=True)
class _Params:
    gap: float = param(0.5, "Keep this far apart.", unit="m", gt=0)
    count: int = param(3, "How many.", ge=1, le=10)
    band: tuple[float, float] = param((0.5, 2.5), "From here to there.", unit="m", ordered=True)
    plain: float = 1.0


def test_a_declared_parameter_is_a_field_with_its_default() -> None:
    assert _Params() == _Params(gap=0.5, count=3, band=(0.5, 2.5), plain=1.0)
    assert _Params(gap=2.0).gap == 2.0
    assert [f.name for f in dataclasses.fields(_Params)] == ["gap", "count", "band", "plain"]


def test_the_declaration_reads_back_with_its_bounds_and_unit() -> None:
    assert param_info(_Params, "gap") == ParamInfo("Keep this far apart.", "m", gt=0)
    assert param_info(_Params, "count").bounds == {"ge": 1, "le": 10}
    assert param_info(_Params, "band").ordered
    assert param_info(_Params, "gap").describe() == "Keep this far apart. Unit: m."
    assert param_info(_Params, "count").describe() == "How many."


def test_a_plain_field_is_no_declared_parameter() -> None:
    with pytest.raises(KeyError, match=r"_Params\.plain is not declared with param\(\)"):
        param_info(_Params, "plain")
    with pytest.raises(KeyError):
        param_info(_Params, "nothing")


def test_the_core_classes_declare_what_a_mission_sets() -> None:
    info = param_info(TrackerParams, "max_coast_s")
    assert info.unit == "s" and info.bounds == {"gt": 0} and info.doc
    assert TrackerParams().max_coast_s == 1.5
