"""How far single-segment leg classification gets on the real labelled bags, and why.

Issue 5 asks for leg precision and recall ≥ 0.9 at 0.5–5 m on the real bags of
``shared/data/legs`` (leg_tracker's data set, Leigh et al. 2015), cross-validated by bag. The
shipped detector reaches 0.78 / 0.54 there, 0.57 / 0.51 one scan at a time
(``pfctl legs evaluate``). This script measures
what other classifiers, temporal evidence and other splits reach on the same segments, so that
the gap is a measured fact rather than a guess.

Run ``python benchmarks/leg_real_ceiling.py [--data ../shared/data/legs]`` (about 1 minute on
two cores). Segments are those of
:func:`pfctl.core.perception.legs.detector.describe_segments` with the shipped
:class:`~pfctl.core.perception.legs.detector.LegParams`, labelled as :mod:`pfctl.app.leg_data`
labels them (positives:
segments at a labelled leg position inside each bag's labelled arc; negatives: every segment of
``negative_2.bag``). Only real scans are used for training: simulated scans lower the real
figures (measured in the closing note of issue 5).

Studies, each printed as precision / recall at P(leg) ≥ 0.5 and at the "break-even" threshold
that maximises the smaller of the two (where they meet, when they do; chosen on the test
outcomes, so optimistic):

- ``forest``: scikit-learn random forest with the shipped settings, leave one group out
  (6 positive bags, and negative_2's three lasers as three groups);
- ``forest, balanced``: the same with ``class_weight="balanced_subsample"`` and trees of
  unlimited depth;
- ``boosting``: ``HistGradientBoostingClassifier``, same folds;
- ``boosting + track mean``: each segment's P(leg) averaged with those of the same segment in
  the previous scans (nearest centroid in the previous scan within 0.35 m, Hungarian matching;
  at most ``--history`` scans; only past scans: usable online);
- ``boosting, random split``: 5 folds drawn at random over segments, ignoring bags — the same
  scenes on both sides, an upper bound for these features;
- ``boosting, strict by bag``: negative_2 held out as one whole bag; its fold trains on the
  positive bags only, with their static background (segments within 5 cm of the per-beam median
  range of a bag recorded by a stationary laser) as the non-legs.

It prints a table and asserts nothing.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from sklearn.ensemble import HistGradientBoostingClassifier, RandomForestClassifier

from pfctl.app.leg_data import SCAN_TOPIC, real_bags, real_sequences
from pfctl.bags.reading import open_bag
from pfctl.core.perception.legs.detector import LegParams, describe_segments
from pfctl.core.perception.legs.evidence import LegEvidence
from pfctl.core.perception.legs.training import (
    EVAL_BAND,
    IGNORE,
    MAX_DEPTH,
    MIN_SAMPLES_LEAF,
    N_TREES,
)

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "legs"
#: A segment of a stationary laser's scan is static background when every return is this close
#: to the per-beam median range over the bag, metres.
STATIC_TOLERANCE = 0.05


@dataclass
class Segments:
    """Every classified segment of the real bags, in bag and scan order."""

    features: np.ndarray
    label: np.ndarray  # 1 leg, 0 non-leg, IGNORE (near a label, or outside the labelled arc)
    group: np.ndarray
    scan: np.ndarray
    xy: np.ndarray
    static: np.ndarray  # static background of a stationary laser (positive bags)
    groups: list[str]

    @property
    def scored(self) -> np.ndarray:
        """Labelled segments in the evaluation band."""
        d = np.hypot(self.xy[:, 0], self.xy[:, 1])
        return (self.label >= 0) & (d >= EVAL_BAND[0]) & (d <= EVAL_BAND[1])


def static_background(path: Path, params: LegParams) -> list[np.ndarray]:
    """Per scan of a positive bag, which of its classified segments (in
    :func:`~pfctl.core.perception.legs.training.scan_segments` order) lie on the static
    background."""
    with open_bag(path) as bag:
        scans = [scan for _, scan in bag.scans(SCAN_TOPIC)]
    ranges = np.array([np.where(np.isfinite(s.ranges), s.ranges, 1e3) for s in scans])
    background = np.median(ranges, axis=0)
    out = []
    for scan, r in zip(scans, ranges, strict=True):
        segs, _, ok = describe_segments(scan, params)
        still = np.abs(r - background) < STATIC_TOLERANCE
        out.append(
            np.array(
                [
                    still[segs.beam[s : s + n]].all()
                    for s, n in zip(segs.start[ok], segs.count[ok], strict=True)
                ],
                dtype=bool,
            )
        )
    return out


def load(directory: Path) -> Segments:
    """Segments, labels and background flags of every real bag."""
    params = LegParams()
    sequences = real_sequences(directory, params)
    positives, _ = real_bags(directory)
    statics = {p.name: static_background(p, params) for p in positives}
    rows: dict[str, list[np.ndarray]] = {k: [] for k in ("f", "l", "g", "s", "xy", "st")}
    for g, (name, scans) in enumerate(sequences):
        for s, seg in enumerate(scans):
            k = len(seg.labels)
            rows["f"].append(seg.features)
            rows["l"].append(seg.labels.astype(int))
            rows["g"].append(np.full(k, g))
            rows["s"].append(np.full(k, s))
            rows["xy"].append(seg.xy)
            rows["st"].append(statics[name][s] if name in statics else np.zeros(k, dtype=bool))
    cat = {k: np.concatenate(v) for k, v in rows.items()}
    groups = [name for name, _ in sequences]
    return Segments(cat["f"], cat["l"], cat["g"], cat["s"], cat["xy"], cat["st"], groups)


Model = Callable[[], object]


def forest(balanced: bool = False) -> Model:
    return lambda: RandomForestClassifier(
        n_estimators=N_TREES,
        max_depth=None if balanced else MAX_DEPTH,
        min_samples_leaf=MIN_SAMPLES_LEAF,
        class_weight="balanced_subsample" if balanced else None,
        random_state=0,
        n_jobs=-1,
    )


def boosting() -> object:
    return HistGradientBoostingClassifier(max_iter=300, learning_rate=0.05, random_state=0)


def out_of_fold(
    data: Segments, make: Model, folds: np.ndarray, train_mask: np.ndarray, labels: np.ndarray
) -> np.ndarray:
    """P(leg) of every segment from a model trained without its fold."""
    prob = np.full(len(labels), np.nan)
    for f in np.unique(folds):
        train = train_mask & (folds != f)
        model = make()
        model.fit(data.features[train], labels[train])  # type: ignore[attr-defined]
        test = folds == f
        prob[test] = model.predict_proba(data.features[test])[:, 1]  # type: ignore[attr-defined]
    return prob


def track_mean(data: Segments, prob: np.ndarray, history: int) -> np.ndarray:
    """Each segment's P(leg) averaged over its track's last ``history`` scans
    (:class:`~pfctl.core.perception.legs.evidence.LegEvidence`, laser frame)."""
    out = prob.copy()
    for g in np.unique(data.group):
        evidence = LegEvidence(history)
        idx = np.flatnonzero(data.group == g)
        for s in np.unique(data.scan[idx]):
            cur = idx[data.scan[idx] == s]
            out[cur] = evidence.update(data.xy[cur], prob[cur])
    return out


def figures(labels: np.ndarray, prob: np.ndarray) -> tuple[float, float, float, float, float]:
    """(P, R) at 0.5, then (P, R, threshold) where P and R meet."""
    y = labels == 1

    def pr(t: float) -> tuple[float, float]:
        hit = prob >= t
        tp = float(np.sum(hit & y))
        return tp / max(float(hit.sum()), 1.0), tp / max(float(y.sum()), 1.0)

    p5, r5 = pr(0.5)
    best = max((min(pr(t)), t) for t in np.linspace(0.01, 0.99, 99))
    pb, rb = pr(best[1])
    return p5, r5, pb, rb, float(best[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="folder of the real leg bags")
    parser.add_argument("--history", type=int, default=10, help="scans in the track mean")
    args = parser.parse_args()
    if not args.data.is_dir():
        raise SystemExit(f"{args.data}: no such folder (the real leg bags of shared/data/legs)")
    t0 = time.perf_counter()
    data = load(args.data)
    lab = data.label
    labelled = lab >= 0
    scored = data.scored
    print(
        f"{len(lab)} segments from {len(data.groups)} groups; scored at "
        f"{EVAL_BAND[0]}–{EVAL_BAND[1]} m: {int(np.sum(scored & (lab == 1)))} legs, "
        f"{int(np.sum(scored & (lab == 0)))} non-legs ({time.perf_counter() - t0:.0f} s)"
    )
    by_group = data.group

    def study(name: str, prob: np.ndarray, labels: np.ndarray = lab, mask: np.ndarray = scored):
        p5, r5, pb, rb, tb = figures(labels[mask], prob[mask])
        print(f"{name:44s} P {p5:.3f} R {r5:.3f} | at {tb:.2f}: P {pb:.3f} R {rb:.3f}")

    print(f"{'study (leave one group out unless said)':44s} at 0.5          | best min(P, R)")
    study("forest (shipped settings)", out_of_fold(data, forest(), by_group, labelled, lab))
    study("forest, balanced", out_of_fold(data, forest(True), by_group, labelled, lab))
    boosted = out_of_fold(data, boosting, by_group, labelled, lab)
    study("boosting", boosted)
    study(f"boosting + track mean of {args.history} scans", track_mean(data, boosted, args.history))
    rng = np.random.default_rng(0)
    random_folds = rng.integers(0, 5, len(lab))
    study(
        "boosting, random split (not by bag)",
        out_of_fold(data, boosting, random_folds, labelled, lab),
    )
    # Strict by bag: negative_2 is one fold, trained without any of its lasers.
    strict_folds = np.array(
        [g if not data.groups[g].startswith("negative") else -1 for g in by_group]
    )
    strict_labels = lab.copy()
    background = (lab == IGNORE) & data.static
    strict_labels[background] = 0
    prob = out_of_fold(data, boosting, strict_folds, (lab >= 0) | background, strict_labels)
    study("boosting, strict by bag (negative_2 whole)", prob)
    print(f"done in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
