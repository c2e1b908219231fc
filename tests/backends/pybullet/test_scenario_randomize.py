"""scenario.randomize: what else the seed varies (speeds, route points, extra distractors,
look-alikes, the hiding region); off by default, seeded, and leaving the other draws alone."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from pfctl.app.sim import sim_config
from pfctl.backends.pybullet.walkers import PERSON_RADIUS, Walker, make_walkers
from pfctl.core.mapping.planning import GridPlanner
from pfctl.errors import MissionError
from pfctl.mission import Mission, ScenarioConfig, loads_mission

pytestmark = pytest.mark.sim

HOUSE = Path(__file__).resolve().parents[3] / "missions" / "house.yaml"


def _make_walkers(mission: Mission, planner: GridPlanner, seed: int) -> list[Walker]:
    return make_walkers(sim_config(mission).scenario, mission.layout(), planner, seed)


def _with(mission: Mission, **randomize: Any) -> Mission:
    scenario = {**mission.scenario.model_dump(), "randomize": randomize}
    return mission.model_copy(update={"scenario": ScenarioConfig.model_validate(scenario)})


def _summary(walkers: list) -> list[tuple]:
    return [
        (w.name, w.cruise, w.clothes, w.height, tuple(np.round(np.ravel(w.stops), 6)))
        for w in walkers
    ]


def test_off_by_default(mission: Mission, planner: GridPlanner) -> None:
    assert mission.scenario.randomize == _with(mission).scenario.randomize
    assert _summary(_make_walkers(mission, planner, 4)) == _summary(
        _make_walkers(_with(mission), planner, 4)
    )


@pytest.mark.slow
def test_randomize_varies_by_seed_and_keeps_the_other_draws(
    mission: Mission, planner: GridPlanner
) -> None:
    varied = _with(
        mission,
        speed_scale=[0.7, 1.3],
        route_jitter=0.6,
        extra_people=[1, 3],
        look_alikes=[1, 2],
        look_alike_jitter=10,
    )
    people = {p.name: p for p in mission.scenario.people}
    target = people[mission.scenario.target]
    counts = set()
    for seed in range(6):
        plain = {w.name: w for w in _make_walkers(mission, planner, seed)}
        walkers = _make_walkers(varied, planner, seed)
        assert _summary(walkers) == _summary(_make_walkers(varied, planner, seed))  # seeded
        named = [w for w in walkers if w.name in people]
        extra = [w for w in walkers if w.name.startswith("extra_")]
        alikes = [w for w in walkers if w.name.startswith("look_alike_")]
        assert len(walkers) == len(named) + len(extra) + len(alikes)
        assert 1 <= len(extra) <= 3 and 1 <= len(alikes) <= 2
        counts.add((len(extra), len(alikes)))
        for w in named:
            person = people[w.name]
            assert 0.7 * person.speed - 1e-9 <= w.cruise <= 1.3 * person.speed + 1e-9
            assert 0.3 <= w.cruise <= 1.4
            assert w.clothes == plain[w.name].clothes and w.height == plain[w.name].height
            for stop, given, before in zip(w.stops, person.route, plain[w.name].stops, strict=True):
                if isinstance(given, str):  # region stops: the same draw as without randomize
                    assert np.allclose(stop, before)
                else:  # points: moved by at most the jitter, to a free spot
                    assert np.linalg.norm(stop - before) <= 0.6 + 1e-9
                    assert planner.with_radius(PERSON_RADIUS).is_free(stop)
        for w in alikes:
            for got, want in (
                (w.clothes.upper, target.clothes.upper),
                (w.clothes.lower, target.clothes.lower),
            ):
                assert np.abs(np.subtract(got, want)).max() <= 10
    assert len(counts) > 1  # the numbers of people change with the seed


def _loads(**randomize: Any) -> Mission:
    data = yaml.safe_load(HOUSE.read_text())
    data["scenario"]["randomize"] = randomize
    if randomize.pop("no_target", False):
        del data["scenario"]["target"]
    return loads_mission(yaml.safe_dump(data), source="m.yaml")


def test_look_alikes_need_a_target_and_hide_in_names_regions() -> None:
    with pytest.raises(MissionError, match=r"randomize\.hide_in\[0\]: unknown region 'attic'"):
        _loads(hide_in=["attic"])
    with pytest.raises(MissionError, match=r"extra_people: expected \[low, high\] with low <="):
        _loads(extra_people=[3, 1])
    with pytest.raises(MissionError, match="look-alikes copy the target's clothes"):
        _loads(look_alikes=[0, 1], no_target=True)
    assert _loads(hide_in=["office", "bedroom"]).scenario.randomize.hide_in == ("office", "bedroom")


def test_search_hides_the_target_in_one_of_hide_in(mission: Mission) -> None:
    from pfctl.app.episodes import hide_target
    from pfctl.backends.pybullet.simulation import SimOptions, SimRobot

    varied = _with(mission, hide_in=["bedroom", "living_room"])
    seen = set()
    for seed in range(4):
        with SimRobot(sim_config(varied, seed), SimOptions(camera=False)) as robot:
            seen.add(hide_target(varied, robot, None))
    assert seen == {"bedroom", "living_room"}
