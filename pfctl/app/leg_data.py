"""Labelled leg data sets for ``pfctl legs``: simulated scans and the real bags (§II-E).

- :func:`sim_dataset`: scans of :mod:`pfctl.backends.pybullet.leg_scans` (the mission's house,
  random furniture and crowds, several lasers), labelled by the true leg circles.
- :func:`real_dataset`: a folder of ROS 1 bags in the layout of the leg_tracker data set (Leigh
  et al. 2015; ``shared/data/legs/README.md``): ``positive_*_extracted.bag`` with
  ``/training_scan`` and ``/leg_cluster_positions`` (each scan preceded by the labelled leg
  positions in its frame; the leg segments are those near a label), and
  ``negative_*.bag`` whose every ``sensor_msgs/LaserScan`` topic has no people. Each bag is a
  group, and each topic of a negative bag is one (``negative_2.bag:/left_scan``), so that
  validation can hold a whole group out.

Only part of each positive scan was labelled. The data set's labels were made by leg_tracker's
``extract_positive_training_clusters``: every cluster whose centroid lies in an arc in front of
the laser (±15°, closer than 5 m; −15° to 10° for ``positive_4``, per its
``extract_positive_training_clusters_res=0.33.launch``) was marked as a leg, and nothing outside
it was looked at: people and furniture beside and behind the laser are unlabelled, so they are
not counted as non-legs either (:data:`LABELLED_ARCS`). leg_tracker itself trains on the
labelled clusters against the negative bags, for the same reason. The non-legs of the real data
are thus those of ``negative_*.bag``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from pfctl.bags.reading import LASER_SCAN, POSE_ARRAY, laser_scan, open_bag, pose_array
from pfctl.core.perception.legs.detector import LegParams
from pfctl.core.perception.legs.training import (
    IGNORE,
    LegDataset,
    ScanSegments,
    scan_samples,
    scan_segments,
)
from pfctl.errors import UserError
from pfctl.mission import Mission

POSITIVE_GLOB = "positive_*_extracted.bag"
NEGATIVE_GLOB = "negative_*.bag"
SCAN_TOPIC = "/training_scan"
LABEL_TOPIC = "/leg_cluster_positions"

#: The labelled part of a positive bag: (min bearing °, max bearing °, max range m).
LABELLED_ARC = (-15.0, 15.0, 5.0)
#: Bags labelled over another arc (leg_tracker's launch file).
LABELLED_ARCS = {"positive_4_extracted.bag": (-15.0, 10.0, 5.0)}

Progress = Callable[[int], None]


def _nothing(_: int) -> None:
    return None


def real_bags(directory: Path) -> tuple[list[Path], list[Path]]:
    """The positive and negative bags of a real data folder; :class:`UserError` if there is
    no such folder or it holds neither."""
    directory = Path(directory)
    if not directory.is_dir():
        raise UserError(f"{directory}: no such folder of real leg bags")
    pos = sorted(directory.glob(POSITIVE_GLOB))
    neg = sorted(directory.glob(NEGATIVE_GLOB))
    if not pos and not neg:
        raise UserError(
            f"{directory}: no leg bags ({POSITIVE_GLOB} with labels, {NEGATIVE_GLOB} without)"
        )
    return pos, neg


def count_real_scans(directory: Path) -> int:
    """How many scans :func:`real_dataset` will read (for a progress bar)."""
    pos, neg = real_bags(directory)
    total = 0
    for path in pos:
        with open_bag(path) as bag:
            total += bag.count(SCAN_TOPIC)
    for path in neg:
        with open_bag(path) as bag:
            total += sum(bag.count(t) for t, m in bag.topics.items() if m == LASER_SCAN)
    return total


#: One group of real scans in recording order: its name and the segments of each scan.
ScanSequence = tuple[str, list[ScanSegments]]


def real_sequences(
    directory: Path, params: LegParams, progress: Progress = _nothing
) -> list[ScanSequence]:
    """The segments of every scan of every bag in ``directory``, scan by scan, one sequence per
    group (see the module docstring; unlabelled segments kept as ``IGNORE`` so that evidence
    over several scans can follow them)."""
    pos, neg = real_bags(directory)
    out: list[ScanSequence] = []
    for path in pos:
        scans: list[ScanSegments] = []
        arc = LABELLED_ARCS.get(path.name, LABELLED_ARC)
        with open_bag(path) as bag:
            bag.require(SCAN_TOPIC, LASER_SCAN)
            bag.require(LABEL_TOPIC, POSE_ARRAY)
            positions = np.empty((0, 2))
            for m in bag.messages([SCAN_TOPIC, LABEL_TOPIC]):
                if m.topic == LABEL_TOPIC:
                    positions = pose_array(m.msg).poses[:, :2]
                    continue
                _, scan = laser_scan(m.msg)
                scans.append(scan_segments(scan, params, positions=positions, labelled_arc=arc))
                positions = np.empty((0, 2))  # labels belong to the scan right after them
                progress(1)
        out.append((path.name, scans))
    for path in neg:
        with open_bag(path) as bag:
            for topic in sorted(t for t, m in bag.topics.items() if m == LASER_SCAN):
                scans = []
                for _, scan in bag.scans(topic):
                    scans.append(scan_segments(scan, params))
                    progress(1)
                out.append((f"{path.name}:{topic}", scans))
    return out


def sequences_dataset(sequences: list[ScanSequence], name: str = "real") -> LegDataset:
    """The labelled segments of ``sequences`` (``IGNORE`` left out), one group per sequence."""
    data = LegDataset(name)
    for group, scans in sequences:
        feats = [s.features[s.labels != IGNORE] for s in scans]
        labels = [s.labels[s.labels != IGNORE] == 1 for s in scans]
        _add(data, group, feats, labels, len(scans))
    return data


def real_dataset(directory: Path, params: LegParams, progress: Progress = _nothing) -> LegDataset:
    """Labelled segments of every bag in ``directory`` (see the module docstring)."""
    return sequences_dataset(real_sequences(directory, params, progress))


def _add(
    data: LegDataset, group: str, feats: list[np.ndarray], labels: list[np.ndarray], scans: int
) -> None:
    if feats:
        data.add(group, np.vstack(feats), np.concatenate(labels), scans)


def sim_dataset(
    mission: Mission, scans: int, seed: int, params: LegParams, progress: Progress = _nothing
) -> LegDataset:
    """Labelled segments of ``scans`` simulated scans (seeded) in the house of ``mission``."""
    from pfctl.app.sim import house_config
    from pfctl.backends.pybullet.leg_scans import LegScanGenerator

    generator = LegScanGenerator(house_config(mission))
    rng = np.random.default_rng(seed)
    data = LegDataset("sim")
    feats, labels = [], []
    for _ in range(scans):
        s = generator.draw(rng)
        f, y = scan_samples(s.scan, params, circles=s.legs)
        feats.append(f)
        labels.append(y)
        progress(1)
    _add(data, f"seed {seed}", feats, labels, scans)
    return data


__all__ = [
    "ScanSequence",
    "count_real_scans",
    "real_bags",
    "real_dataset",
    "real_sequences",
    "sequences_dataset",
    "sim_dataset",
]
