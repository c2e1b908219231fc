"""The episode of a ``pfctl bench`` campaign: what ``pfctl follow`` / ``pfctl search --backend sim
--seed SEED`` does, headless, measured for the campaign's record.

Learn the target in the simulator with the episode's seed (the faces depend on it), build the
simulated house with that seed, for ``search`` hide the target (a region chosen by the seed, or
one of ``scenario.randomize.hide_in``), run the mission's follower for the duration, and measure
(:mod:`pfctl.core.metrics`). :mod:`pfctl.bench` runs it in worker processes or as Ray tasks
(:func:`pfctl.bench.episode.run_episode_task`) and keeps the records.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from rich.console import Console

from pfctl.app.episodes import hide_target, metric_params, run_sim_episode, target_profile
from pfctl.bench.plan import EpisodeSpec
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.metrics import follow_metrics, room_prediction_scores, search_metrics

#: How the follower re-acquired a lost target (:class:`~pfctl.core.metrics.Reacquisition`).
HOW = ("prediction", "waypoint_search", "other")


def run_campaign_episode(spec: EpisodeSpec) -> tuple[str, dict[str, Any], dict[str, Any]]:
    """The episode of ``spec`` (module docstring): its status (``ok``, or ``timeout`` when the
    spec's wall-clock limit ended it), metrics and timing."""
    from pfctl.app.sim import sim_robot  # loads PyBullet: in the worker, not when the CLI starts

    mission = spec.mission
    source = f"{spec.mission_file} [{spec.variant}]"
    start = time.perf_counter()
    deadline = start + spec.timeout if spec.timeout > 0 else math.inf
    profile = target_profile(mission, None, spec.seed, Console(stderr=True, quiet=True), source)
    learn_s = time.perf_counter() - start
    robot = sim_robot(mission, spec.seed, source)
    region = None
    with robot:
        if spec.task == "search":
            region = hide_target(mission, robot, None)
        result = run_sim_episode(
            mission,
            robot,
            profile,
            spec.duration,
            stop=lambda: time.perf_counter() > deadline,
            until_found=spec.task == "search",
        )
    params = metric_params(mission)
    if spec.task == "search":
        found = search_metrics(result.log, params)
        metrics: dict[str, Any] = {
            "found": found.found,
            "time_to_find_s": found.time_to_find_s,
            "distance_m": found.distance_m,
            "collisions": found.collisions,
            "region": region,
        }
    else:
        follow = follow_metrics(result.log, params)
        metrics = {
            "following_rate": follow.following_rate,
            "first_identified_s": follow.first_identified_s,
            "losses": follow.losses,
            "reacquired": len(follow.reacquisitions),
            "unrecovered_losses": follow.unrecovered_losses,
            **{f"by_{how}": sum(r.how == how for r in follow.reacquisitions) for how in HOW},
            "refind_times_s": [r.time_to_refind for r in follow.reacquisitions],
            "median_time_to_refind_s": follow.median_time_to_refind_s,
            "identity_switches": follow.identity_switches,
            "collisions": follow.collisions,
            "distance_m": follow.distance_m,
            "duration_s": follow.duration_s,
            **room_prediction_scores(result.log, RegionMap(mission.layout()), params).to_json(),
        }
    metrics["sim_time_s"] = result.sim_time
    ticks = 1000.0 * np.asarray(result.tick_seconds, dtype=float)
    timing = {
        "wall_s": time.perf_counter() - start,
        "learn_wall_s": learn_s,
        "episode_wall_s": result.wall_time,
        "tick_ms_median": float(np.median(ticks)) if len(ticks) else None,
        "tick_ms_p99": float(np.percentile(ticks, 99)) if len(ticks) else None,
    }
    return ("timeout" if result.interrupted else "ok"), metrics, timing


__all__ = ["HOW", "run_campaign_episode"]
