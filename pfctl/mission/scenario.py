"""The ``scenario`` section: the simulator's episode — its seed, the people and their routes,
which of them is the target, and what else the seed varies in benchmark campaigns."""

from __future__ import annotations

from typing import Annotated, Any, Union

from pydantic import AfterValidator, Discriminator, Field, Tag, model_validator

from pfctl.mission.errors import raise_first, value_error
from pfctl.mission.types import NO_BOOL, RGB, MissionModel, Name, NonNegative, Point, Seed


def _route_stop_kind(value: Any) -> str | None:
    if isinstance(value, str):
        return "region"
    if isinstance(value, (list, tuple)):
        return "point"
    return None


RouteStop = Annotated[
    Union[Annotated[Name, Tag("region")], Annotated[Point, Tag("point")]],  # noqa: UP007
    Discriminator(
        _route_stop_kind,
        custom_error_type="route_stop",
        custom_error_message="expected a region name or an [x, y] point",
    ),
]
"""A stop of a person's route: the name of a region (its centre) or an ``[x, y]`` point."""


class Clothes(MissionModel):
    """Colours of a simulated person's clothes, RGB 0..255 (Algorithm 2 compares histograms)."""

    upper: RGB
    lower: RGB


class Person(MissionModel):
    """A simulated person: name, clothes, walking speed (m/s) and route."""

    name: Name
    clothes: Clothes
    speed: Annotated[float, Field(ge=0.3, le=1.4), NO_BOOL] = 0.8
    route: Annotated[tuple[RouteStop, ...], Field(min_length=1)]
    """Region names or [x, y] points, walked in order; the person starts at the first."""
    height: Annotated[float, Field(ge=1.2, le=2.1), NO_BOOL] = 1.7
    """Body height, metres (simulator)."""
    pause_s: NonNegative = 2.0
    """Mean pause at each intermediate stop of the route, seconds."""
    loop: bool = False
    """Walk the route again and again (back to the first stop); else stay at the last stop."""


PeopleCount = Annotated[int, Field(ge=0, le=20), NO_BOOL]


def _check_range(value: tuple[Any, Any]) -> tuple[Any, Any]:
    """A ``[low, high]`` range must have ``low <= high`` (equal: a fixed value)."""
    if value[0] > value[1]:
        raise value_error(
            "range_order", f"expected [low, high] with low <= high, got [{value[0]}, {value[1]}]"
        )
    return value


CountRange = Annotated[tuple[PeopleCount, PeopleCount], AfterValidator(_check_range)]
"""An inclusive ``[low, high]`` range of a number of people, each drawn uniformly."""
ScaleRange = Annotated[
    tuple[
        Annotated[float, Field(ge=0.25, le=4.0), NO_BOOL],
        Annotated[float, Field(ge=0.25, le=4.0), NO_BOOL],
    ],
    AfterValidator(_check_range),
]
"""A ``[low, high]`` range of a factor, drawn uniformly."""


class ScenarioRandomization(MissionModel):
    """What else the seed varies from episode to episode (``pfctl bench`` campaigns).

    Everything is off by default, so a mission without this section runs exactly as before. The
    draws come from their own random streams of the seed: turning one on leaves everything the
    seed already varied (region stops, pauses, ``random_people``, faces, sensor noise) as it was.
    """

    speed_scale: ScaleRange = (1.0, 1.0)
    """Each of ``people`` walks at their ``speed`` times a factor drawn from this range (the
    result kept within a person's 0.3-1.4 m/s)."""
    route_jitter: NonNegative = 0.0
    """Each ``[x, y]`` stop of the ``people``'s routes moves by up to this many metres, to a
    free spot of the same region (region stops are already a random free point of the region)."""
    extra_people: CountRange = (0, 0)
    """Distractors added to ``random_people``: their number drawn from this range."""
    look_alikes: CountRange = (0, 0)
    """Distractors dressed like the target (each colour channel within ``look_alike_jitter``),
    walking random looping routes: their number drawn from this range."""
    look_alike_jitter: Annotated[int, Field(ge=0, le=128), NO_BOOL] = 12
    """How far a look-alike's clothes may stray from the target's, per RGB channel (0..255)."""
    hide_in: tuple[Name, ...] = ()
    """``pfctl search``/``bench --task search``: the target hides in one of these regions, chosen
    by the seed (empty: any region that is not the robot's or next to it)."""


class ScenarioConfig(MissionModel):
    """The simulator's episode: seed, the people, and which of them is the target."""

    seed: Seed = 0
    target: str | None = None
    """The name of the person to follow: one of ``people``."""
    people: tuple[Person, ...] = ()
    random_people: PeopleCount = 0
    """Extra distractors with random clothes, speeds and looping routes drawn from ``seed``."""
    randomize: ScenarioRandomization = ScenarioRandomization()
    """Further per-seed variation for benchmark campaigns; all off by default."""
    turn_to_voice: bool = True
    """People standing within earshot of the robot (4 m, no wall between) turn to face it when
    it speaks, and back after a few seconds, as people do (false: they never do)."""

    @model_validator(mode="after")
    def _names(self) -> ScenarioConfig:
        issues: list[tuple[tuple[str | int, ...], str]] = []
        seen: dict[str, int] = {}
        for i, person in enumerate(self.people):
            if person.name in seen:
                issues.append(
                    (
                        ("people", i, "name"),
                        f"duplicate person name {person.name!r} "
                        f"(already used by people[{seen[person.name]}])",
                    )
                )
            seen.setdefault(person.name, i)
        if self.target is not None and self.target not in seen:
            names = ", ".join(seen) or "none"
            issues.append(
                (
                    ("target",),
                    f"expected the name of one of the people ({names}), got {self.target!r}",
                )
            )
        if self.target is None and self.randomize.look_alikes[1] > 0:
            issues.append(
                (
                    ("randomize", "look_alikes"),
                    "look-alikes copy the target's clothes: name a scenario.target first",
                )
            )
        raise_first(issues)
        return self
