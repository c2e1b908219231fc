"""The campaign: which episodes to run, and the fingerprint of its configuration.

An episode is identified by (mission file, variant, seed) — :attr:`EpisodeSpec.key`. Episode
``i`` of every mission and variant has the seed ``seed + i``, so variants are compared on the same
scenarios (the seed draws the routes' stops, pauses, distractors, faces, sensor noise and what
``scenario.randomize`` varies). Episodes are listed seed-major: a campaign cut short still holds
every variant on its first seeds.

The campaign's *fingerprint* hashes what makes its results comparable: the task, the simulated
duration, the first seed, and every (mission file, variant) with the mission it resolves to
(validated, defaults left out — so a new field with a default does not change it). The number of
episodes is not in it: a campaign may be extended with ``--resume --episodes`` more.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import yaml

from pfctl.bench.variants import Variant, apply_overrides
from pfctl.errors import MissionError, UserError
from pfctl.mission import Mission, load_mission, loads_mission

__all__ = [
    "TASKS",
    "Campaign",
    "EpisodeSpec",
    "MissionVariant",
    "Task",
    "load_variant",
    "mission_digest",
    "mission_labels",
]

Task = Literal["follow", "search"]
#: What an episode does: follow the target (``pfctl follow``) or find them (``pfctl search``).
TASKS: tuple[Task, ...] = ("follow", "search")


@dataclass(frozen=True)
class MissionVariant:
    """One mission file under one variant: what a group of episodes runs."""

    label: str
    """The mission's short name in tables (the file's stem, or its path when stems collide)."""
    path: str
    """The mission file as given (normalised), part of each episode's identity."""
    variant: Variant
    mission: Mission
    """The mission with the variant's overrides, validated."""
    digest: str
    """:func:`mission_digest` of ``mission``."""


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode, all a worker needs to run it (picklable; the mission travels with it)."""

    mission_label: str
    mission_file: str
    variant: str
    index: int
    seed: int
    task: Task
    duration: float
    """Simulated seconds (search: the most; it ends when the target is found)."""
    timeout: float
    """Wall seconds after which the episode is ended (status ``timeout``); 0: no limit."""
    config: str
    """The campaign's fingerprint, stored with the result."""
    mission: Mission = field(repr=False, compare=False)

    @property
    def key(self) -> tuple[str, str, int]:
        """The episode's identity: (mission file, variant, seed)."""
        return (self.mission_file, self.variant, self.seed)


@dataclass(frozen=True)
class Campaign:
    """Missions × variants × episodes of one task; see the module docstring."""

    task: Task
    groups: tuple[MissionVariant, ...]
    episodes: int
    seed: int
    duration: float
    timeout: float = 0.0

    def config(self) -> dict[str, Any]:
        """What the fingerprint hashes, as JSON-able data (``campaign.json`` holds it)."""
        return {
            "task": self.task,
            "duration_s": self.duration,
            "seed": self.seed,
            "groups": [
                {"mission": g.label, "file": g.path, "variant": g.variant.name, "digest": g.digest}
                for g in self.groups
            ],
        }

    @property
    def fingerprint(self) -> str:
        """16 hex digits of the SHA-256 of :meth:`config` (canonical JSON)."""
        text = json.dumps(self.config(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]

    @property
    def seeds(self) -> list[int]:
        """The episodes' seeds: ``seed + i``."""
        return [self.seed + i for i in range(self.episodes)]

    def specs(self) -> list[EpisodeSpec]:
        """Every episode, seed-major (all groups on the first seed, then the next)."""
        config = self.fingerprint
        return [
            EpisodeSpec(
                mission_label=g.label,
                mission_file=g.path,
                variant=g.variant.name,
                index=i,
                seed=self.seed + i,
                task=self.task,
                duration=self.duration,
                timeout=self.timeout,
                config=config,
                mission=g.mission,
            )
            for i in range(self.episodes)
            for g in self.groups
        ]


def mission_digest(mission: Mission) -> str:
    """16 hex digits of the SHA-256 of the mission's non-default values (canonical JSON)."""
    data = mission.model_dump(mode="json", exclude_defaults=True)
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def mission_labels(paths: list[str]) -> list[str]:
    """File stems, or the paths themselves when two stems collide."""
    stems = [Path(p).stem for p in paths]
    return stems if len(set(stems)) == len(stems) else list(paths)


def load_variant(path: str | os.PathLike[str], variant: Variant) -> Mission:
    """The mission at ``path`` with ``variant``'s overrides applied to its YAML data, validated.

    Raises:
        UserError: the file itself is bad (the mission's own one-line error), or the variant
            makes it bad (``FILE with --vary NAME: key.path: what was expected``).
    """
    source = os.fspath(path)
    base = load_mission(source)  # the file's own errors first, with their lines
    if not variant.overrides:
        return base
    data = yaml.safe_load(Path(source).read_text(encoding="utf-8"))
    varied = apply_overrides(data, variant.overrides)
    text = yaml.safe_dump(varied, sort_keys=False, allow_unicode=True)
    try:
        return loads_mission(text, source=source, base_dir=Path(source).parent)
    except MissionError as err:
        # the line numbers would be those of the re-dumped text: name the variant instead
        message = re.sub(rf"^{re.escape(source)}(:\d+)?: ", "", str(err))
        raise UserError(f"{source} with --vary {variant.name}: {message}") from None
