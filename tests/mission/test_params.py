"""Mission keys that the core declares (pfctl.mission.params): derived from the core's
declaration (type, default, bounds, description), and the core parameters built back from them."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Annotated, Literal

import pytest
from pydantic import BaseModel, Field

from pfctl.app.follower import control_params, follower_params
from pfctl.app.perception import belief_params, identity_params, leg_params, tracker_params
from pfctl.core.control import ControlParams
from pfctl.core.follower import FollowerParams, PredictionParams
from pfctl.core.mapping.grid import InverseSensorModel
from pfctl.core.mapping.regions import SearchParams
from pfctl.core.metrics import MetricParams
from pfctl.core.params import param, param_info
from pfctl.core.perception.belief import BeliefParams
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.identity.params import IdentityParams, resolve_face_timing
from pfctl.core.perception.legs.detector import LegParams
from pfctl.core.perception.tracking import TrackerParams
from pfctl.core.prediction.models import SvrState
from pfctl.errors import MissionError
from pfctl.mission import Mission, loads_mission
from pfctl.mission.errors import models_in
from pfctl.mission.params import CoreSection, FromCore, core_params, core_values
from pfctl.mission.types import NO_BOOL, Count, Limits, MissionModel, NonNegative, Positive

MINIMAL = """\
name: minimal
map:
  regions:
    - {name: room, polygon: [[0, 0], [4, 0], [4, 3], [0, 3]]}
"""


def _sections(model: type[BaseModel], seen: set[type[BaseModel]]) -> Iterator[type[BaseModel]]:
    """``model`` and the models of its fields, through nested ones, each once."""
    seen.add(model)
    yield model
    for info in model.model_fields.values():
        for sub in models_in(info.annotation):
            if sub not in seen:
                yield from _sections(sub, seen)


CORE_SECTIONS = sorted(
    (s for s in _sections(Mission, set()) if issubclass(s, CoreSection) and s.core_fields),
    key=lambda s: s.__name__,
)


def test_every_core_key_has_the_core_default_and_meaning() -> None:
    """One declaration: the mission's default and description are the core field's."""
    assert len(CORE_SECTIONS) == 13
    keys = 0
    for section in CORE_SECTIONS:
        for key, (source, name) in section.core_fields.items():
            field = section.model_fields[key]
            core = next(f for f in dataclasses.fields(source) if f.name == name)
            assert field.default == core.default, f"{section.__name__}.{key}"
            assert field.description == param_info(source, name).describe()
            keys += 1
    assert keys == 69


def test_the_default_mission_builds_the_core_defaults() -> None:
    mission = loads_mission(MINIMAL)
    assert leg_params(mission) == LegParams()
    assert tracker_params(mission) == TrackerParams()
    assert belief_params(mission) == BeliefParams()
    assert identity_params(mission) == IdentityParams(face_timing="deterministic")
    assert control_params(mission) == ControlParams()
    assert follower_params(mission) == FollowerParams(
        prediction=PredictionParams(
            params={
                "C": 1000.0,
                "epsilon": 0.01,
                "gamma": 0.01,
                "weighting": "exponential",
                "half_life_s": 0.5,
            }
        )
    )
    assert follower_params(mission).search == SearchParams()
    assert core_params(InverseSensorModel, mission.map.sensor_model) == InverseSensorModel()
    assert core_params(MetricParams, mission.control) == MetricParams()


def test_a_mission_value_reaches_the_core_by_its_core_name() -> None:
    mission = loads_mission(
        MINIMAL
        + """\
robot: {radius: 0.3, head_pan_limits: [-1, 1]}
sensors: {camera: {mount_height: 1.2}}
control: {following_band: [0.4, 3]}
prediction: {weighting: {kind: linear}}
perception: {identity: {bins: [8, 8, 8], face_miss_limit: 5}}
"""
    )
    control = control_params(mission)
    assert (control.robot_radius, control.pan_limits, control.camera_height) == (
        0.3,
        (-1.0, 1.0),
        1.2,
    )
    assert core_params(MetricParams, mission.control).band == (0.4, 3.0)
    assert follower_params(mission).prediction.params["weighting"] == "linear"
    assert core_values(SvrState, mission.prediction.weighting) == {
        "weighting": "linear",
        "half_life_s": 0.5,
    }
    identity = identity_params(mission)
    assert identity.clothes == ClothesParams("hsv", (8, 8, 8)) and identity.face_miss_limit == 5


def test_the_static_scene_filter_is_off_by_default_and_a_mission_turns_it_on() -> None:
    assert leg_params(loads_mission(MINIMAL)).static_after_s == 0.0
    on = loads_mission(MINIMAL + "perception: {legs: {static_after_s: 0.5}}\n")
    assert leg_params(on).static_after_s == 0.5
    with pytest.raises(
        MissionError, match=r"perception\.legs\.static_after_s: expected a value >= 0"
    ):
        loads_mission(MINIMAL + "perception: {legs: {static_after_s: -1}}\n")


def test_face_timing_auto_is_deterministic_in_the_simulator_and_realtime_on_a_robot() -> None:
    mission = loads_mission(MINIMAL)
    assert mission.perception.identity.face_timing == "auto" == IdentityParams().face_timing
    assert identity_params(mission, "sim").face_timing == "deterministic"
    assert identity_params(mission, "real").face_timing == "realtime"
    assert identity_params(mission, "real", "deterministic").face_timing == "deterministic"
    assert IdentityParams().timing == "deterministic"
    assert resolve_face_timing("realtime", on_robot=False) == "realtime"
    fixed = loads_mission(MINIMAL + "perception: {identity: {face_timing: deterministic}}\n")
    assert identity_params(fixed, "real").face_timing == "deterministic"


def test_the_derived_bounds_give_the_mission_messages() -> None:
    with pytest.raises(MissionError, match=r"tracking\.gate: expected a value > 0 \(got 0\)"):
        loads_mission(MINIMAL + "tracking: {gate: 0}\n")
    with pytest.raises(MissionError, match=r"expected \[low, high\] with low < high, got \[2, 1\]"):
        loads_mission(MINIMAL + "control: {following_band: [2, 1]}\n")
    with pytest.raises(
        MissionError, match=r"perception\.identity\.bins\[1\]: expected a value >= 1"
    ):
        loads_mission(MINIMAL + "perception: {identity: {bins: [8, 0, 8]}}\n")


@dataclass(frozen=True)
class _Core:
    gap: float = param(0.5, "Keep this far apart.", unit="m", gt=0)
    slack: float = param(0.0, "Extra room.", unit="m", ge=0)
    reach: float = param(1.0, "At least this far.", unit="m", ge=0.3)
    bins: tuple[int, int] = param((4, 4), "Bins.", ge=1)
    band: tuple[float, float] = param((0.5, 2.5), "From here to there.", ordered=True)
    mode: Literal["a", "b"] = param("a", "Which one.")
    hidden: int = 7


class _Derived(CoreSection, core=_Core, core_names={"distance": "gap"}):
    """A section."""

    distance: FromCore
    slack: FromCore
    name: str = "x"
    reach: FromCore
    bins: FromCore
    band: FromCore
    mode: FromCore


class _HandWritten(MissionModel):
    """A section."""

    distance: Positive = Field(0.5, description="Keep this far apart. Unit: m.")
    slack: NonNegative = Field(0.0, description="Extra room. Unit: m.")
    name: str = "x"
    reach: Annotated[float, Field(ge=0.3), NO_BOOL] = Field(
        1.0, description="At least this far. Unit: m."
    )
    bins: tuple[Count, Count] = Field((4, 4), description="Bins.")
    band: Limits = Field((0.5, 2.5), description="From here to there.")
    mode: Literal["a", "b"] = Field("a", description="Which one.")


def test_a_derived_section_is_the_section_written_by_hand() -> None:
    derived, by_hand = _Derived.model_json_schema(), _HandWritten.model_json_schema()
    derived["title"] = by_hand["title"]
    assert derived == by_hand
    assert list(_Derived.model_fields) == [
        "distance",
        "slack",
        "name",
        "reach",
        "bins",
        "band",
        "mode",
    ]
    assert _Derived.core_fields["distance"] == (_Core, "gap")
    assert core_params(_Core, _Derived(distance=2.0)) == _Core(gap=2.0)
    for bad in ({"slack": float("inf")}, {"distance": True}, {"band": (1, 1)}):
        with pytest.raises(ValueError):
            _Derived(**bad)
    assert _Derived(reach=float("inf")).reach == float("inf")  # as the hand-written field


def test_a_section_naming_no_core_field_is_a_mistake() -> None:
    with pytest.raises(TypeError, match=r"_Bad\.nothing: no field 'nothing' in _Core"):

        class _Bad(CoreSection, core=_Core):
            nothing: FromCore

    with pytest.raises(TypeError, match=r"_Bad2: core_names for keys it lacks: \['other'\]"):

        class _Bad2(CoreSection, core=_Core, core_names={"other": "gap"}):
            gap: FromCore

    with pytest.raises(KeyError, match=r"_Core\.hidden is not declared with param\(\)"):

        class _Bad3(CoreSection, core=_Core):
            hidden: FromCore
