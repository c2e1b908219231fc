"""Where people are lost on the real annotated bag: segmentation, leg classification, candidates.

Issue 24 asks for MOTA ≥ 20 % on ``general_tracking_moving_1.bag`` (Leigh et al.'s annotated
moving-robot bag, 7.5 Hz, 768 beams). ``pfctl track evaluate`` scores the whole perception; this
script measures, per annotated person at the scan they annotate (the laser's frame), how far each
stage of the laser perception gets, so that the stage that loses them is a measured fact:

- ``segment``: a segment the detector classifies (``min_points``, ``max_range``) within 0.35 m;
- ``leg P ≥ t``: such a segment with P(leg) ≥ t, one scan alone (``history_scans: 1``), for the
  model(s) given; beside it the segments per annotated scan at ≥ t farther than 0.5 m from every
  annotated person (clutter the tracker would have to reject);
- ``candidate``: a person candidate of :class:`~pfctl.core.perception.legs.detector.LegDetector`
  within 0.5 m, for a few ``perception.legs`` settings (scans fed in order, so the evidence over
  scans works as in a replay), and the candidates farther than 0.75 m from everyone per scan.

Run ``python benchmarks/real_tracking_ceiling.py [--data ../shared/data/legs] [--model M.npz
...]`` (about 30 s). It prints tables and asserts nothing.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

from pfctl.app.leg_models import load_leg_model
from pfctl.bags.annotations import read_annotations
from pfctl.bags.replay import open_replay
from pfctl.core.perception.legs.detector import LegDetector, LegParams, classify_segments
from pfctl.core.perception.legs.model import LegModel
from pfctl.core.robot import LaserScan, Pose2D

BAG = "general_tracking_moving_1.bag"
THRESHOLDS = (0.05, 0.1, 0.2, 0.3, 0.5)
SETTINGS = {
    "shipped defaults": LegParams(),
    "history_scans 1": LegParams(history_scans=1),
    "history 1, P ≥ 0.3": LegParams(history_scans=1, probability=0.3),
    "history 1, P ≥ 0.2, one leg ≥ 0.4": LegParams(
        history_scans=1, probability=0.2, single_leg_probability=0.4
    ),
}


def _annotated(data: Path) -> tuple[list[LaserScan], dict[int, np.ndarray]]:
    """The bag's posed scans and, by scan index, the annotated positions (laser frame)."""
    source = open_replay(data / BAG, scan_topic="/scan", frame="odom", camera=False)
    with source.bag:
        annotations = read_annotations(source.bag, "/ground_truth_people_tracks", "/scan")
        scans = [s for s in source.stream() if isinstance(s, LaserScan)]
    index = {s.stamp: i for i, s in enumerate(scans)}
    return scans, {index[a.scan_stamp]: a.xy for a in annotations if a.scan_stamp in index}


def _distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])


def segment_table(
    scans: list[LaserScan], people: dict[int, np.ndarray], models: dict[str, LegModel]
) -> None:
    params = LegParams(history_scans=1)
    total = sum(len(xy) for xy in people.values())
    for name, model in models.items():
        found = dict.fromkeys(THRESHOLDS, 0)
        clutter = dict.fromkeys(THRESHOLDS, 0)
        segment = 0
        for i, xy in people.items():
            c = classify_segments(replace(scans[i], pose=Pose2D(0.0, 0.0, 0.0)), model, params)
            d = _distances(c.segments.centroids()[c.classified], xy)
            p = c.probability[c.classified]
            segment += int((d < 0.35).any(axis=0).sum())
            for t in THRESHOLDS:
                found[t] += int((d[p >= t] < 0.35).any(axis=0).sum())
                clutter[t] += int((~(d[p >= t] < 0.5).any(axis=1)).sum())
        cells = "  ".join(
            f"≥{t}: {found[t] / total:4.0%} ({clutter[t] / len(people):.2f})" for t in THRESHOLDS
        )
        print(f"{name:<10} segment {segment / total:4.0%}  leg P {cells}")


def candidate_table(scans: list[LaserScan], people: dict[int, np.ndarray], model: LegModel) -> None:
    total = sum(len(xy) for xy in people.values())
    for name, params in SETTINGS.items():
        detector = LegDetector(model, params)
        hit = spurious = 0
        for i, scan in enumerate(scans):
            found = detector.detect(scan)
            if i not in people or not found.people:
                continue
            xy = scan.pose.inverse().transform(np.array([(p.x, p.y) for p in found.people]))
            d = _distances(xy, people[i])
            hit += int((d < 0.5).any(axis=0).sum())
            spurious += int((~(d < 0.75).any(axis=1)).sum())
        print(
            f"{name:<36} candidate within 0.5 m {hit / total:4.0%}, "
            f"others {spurious / len(people):.2f} per annotated scan"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = Path(__file__).resolve().parents[1]
    parser.add_argument("--data", type=Path, default=root.parent / "shared" / "data" / "legs")
    parser.add_argument("--model", type=Path, action="append", default=[], help="other models")
    args = parser.parse_args()
    scans, people = _annotated(args.data)
    total = sum(len(xy) for xy in people.values())
    print(f"{BAG}: {total} annotated people at {len(people)} scans")
    models = {"shipped": load_leg_model()}
    models.update({path.stem: load_leg_model(path) for path in args.model})
    print("per annotated person: a classified segment within 0.35 m, and one with P(leg) ≥ t "
          "(in brackets: segments ≥ t farther than 0.5 m from everyone, per scan)")  # fmt: skip
    segment_table(scans, people, models)
    print("person candidates of the shipped model (scans in order):")
    candidate_table(scans, people, models["shipped"])


if __name__ == "__main__":
    main()
