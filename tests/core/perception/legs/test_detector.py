"""Leg detection (§II-E): segmentation, Arras et al. 2007 features, the npz forest, pairing."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from sklearn.ensemble import RandomForestClassifier

from pfctl.app.leg_models import load_leg_model
from pfctl.core.perception.legs.detector import (
    LegDetector,
    LegParams,
    classify_scans,
    classify_segments,
    describe_segments,
    pair_legs,
)
from pfctl.core.perception.legs.features import (
    FEATURE_NAMES,
    MAX_JUMP,
    Segments,
    segment_features,
    segment_scan,
    segment_scans,
)
from pfctl.core.perception.legs.model import LegModel
from pfctl.core.perception.legs.training import LegDataset, label_by_positions, score, train_forest
from pfctl.core.robot import LaserScan, Pose2D

F = {name: i for i, name in enumerate(FEATURE_NAMES)}


def _one_segment(points: np.ndarray) -> Segments:
    """``points`` (laser frame, in scan order) as the only segment of a scan."""
    n = len(points)
    return Segments(points, np.arange(n), np.array([0]), np.array([n]))


def test_segmentation_breaks_at_jumps_and_skips_missing_returns() -> None:
    inc = math.radians(1.0)
    r = np.array([2.0, 2.0, 2.0, 3.0, 3.0, np.inf, 3.0, 3.0, 0.0, 3.0, np.nan, 3.0, 4.0])
    segs = segment_scan(r, 0.0, inc, 0.05, 20.0, jump_distance=0.13)
    # Beams without return are skipped (leg_tracker's clustering), jumps still cut.
    assert segs.count.tolist() == [3, 6, 1]
    assert segs.beam.tolist() == [0, 1, 2, 3, 4, 6, 7, 9, 11, 12]
    assert np.allclose(segs.centroids()[0], np.mean(segs.points(0), axis=0))


def test_context_features_find_the_other_leg() -> None:
    # Two small arcs 0.3 m apart (a person's legs), a wide wall far off, a lone 2-point blip.
    leg = 0.05 * np.column_stack(
        (np.cos(np.linspace(2.5, 3.8, 6)), np.sin(np.linspace(2.5, 3.8, 6)))
    )
    parts = [
        leg + np.array([2.0, 0.0]),
        leg + np.array([2.0, 0.3]),
        np.column_stack((np.full(20, 4.0), np.linspace(1, 3, 20))),
        np.array([[-2.0, -2.0], [-2.0, -2.01]]),
    ]
    xy = np.vstack(parts)
    count = np.array([len(p) for p in parts])
    start = np.concatenate(([0], np.cumsum(count)[:-1]))
    f = segment_features(Segments(xy, np.arange(len(xy)), start, count))
    assert f[0, F["partner_distance"]] == pytest.approx(0.3)
    assert f[1, F["partner_distance"]] == pytest.approx(0.3)
    assert f[0, F["partner_width"]] == pytest.approx(f[1, F["width"]])
    # The wall is too wide and the blip too short to be a leg; nothing within 3 m of the blip.
    assert f[3, F["partner_distance"]] == MAX_JUMP
    assert f[3, F["partner_width"]] == 0.0
    assert f[:, F["neighbours"]].tolist() == [1, 1, 0, 0]


def test_segmentation_of_an_empty_scan() -> None:
    segs = segment_scan(np.full(10, np.inf), 0.0, 0.01, 0.05, 20.0, 0.13)
    assert len(segs) == 0
    assert segment_features(segs).shape == (0, len(FEATURE_NAMES))


def test_features_of_a_circle_arc() -> None:
    r, centre = 0.06, np.array([1.5, 0.2])
    phi = np.linspace(math.pi - 1.2, math.pi + 1.2, 25)  # the side facing the laser
    pts = centre + r * np.column_stack((np.cos(phi), np.sin(phi)))
    f = segment_features(_one_segment(pts))[0]
    assert f[F["radius"]] == pytest.approx(r, rel=0.05)
    assert f[F["circularity"]] < 1e-6
    assert f[F["linearity"]] > 1e-4
    assert f[F["mean_curvature"]] == pytest.approx(1 / r, rel=0.1)
    assert f[F["distance"]] == pytest.approx(np.linalg.norm(pts.mean(axis=0)), abs=1e-3)
    assert f[F["jump_preceding"]] == MAX_JUMP
    assert f[F["width"]] == pytest.approx(2 * r * math.sin(1.2), rel=0.05)


def test_features_of_a_straight_line() -> None:
    y = np.linspace(-0.5, 0.5, 40)
    pts = np.column_stack((np.full_like(y, 2.0), y))
    f = segment_features(_one_segment(pts))[0]
    assert f[F["points"]] == 40
    assert f[F["linearity"]] == pytest.approx(0.0, abs=1e-12)
    assert f[F["width"]] == pytest.approx(1.0)
    assert f[F["boundary_length"]] == pytest.approx(1.0)
    assert f[F["boundary_regularity"]] == pytest.approx(0.0, abs=1e-9)
    assert f[F["mean_curvature"]] == pytest.approx(0.0, abs=1e-6)
    assert f[F["std_centroid"]] == pytest.approx(np.sqrt(np.sum(y**2) / 39))


def test_jumps_to_neighbouring_segments() -> None:
    inc = math.radians(1.0)
    r = np.array([2.0, 2.0, 2.0, 1.0, 1.0, 1.0])
    segs = segment_scan(r, 0.0, inc, 0.05, 20.0, 0.13)
    f = segment_features(segs)
    gap = np.linalg.norm(segs.xy[3] - segs.xy[2])
    assert f[0, F["jump_succeeding"]] == pytest.approx(gap)
    assert f[1, F["jump_preceding"]] == pytest.approx(gap)


def _forest(seed: int = 0) -> tuple[RandomForestClassifier, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(400, len(FEATURE_NAMES)))
    y = (x[:, 0] + 0.5 * x[:, 3] ** 2 + rng.normal(0, 0.3, 400) > 0.5).astype(int)
    forest = RandomForestClassifier(n_estimators=7, max_depth=8, random_state=seed).fit(x, y)
    return forest, rng.normal(size=(300, len(FEATURE_NAMES)))


def test_npz_model_round_trips_and_matches_sklearn() -> None:
    forest, x = _forest()
    model = LegModel.from_forest(forest, FEATURE_NAMES, {"seed": 0})
    data = model.to_bytes()
    loaded = LegModel.from_bytes(data, FEATURE_NAMES)
    assert loaded.metadata == {"seed": 0}
    assert loaded.n_trees == 7
    np.testing.assert_allclose(loaded.predict_proba(x), forest.predict_proba(x)[:, 1], atol=1e-6)
    with np.load(io.BytesIO(data), allow_pickle=False) as arrays:  # plain arrays only
        assert int(arrays["version"]) == 1


def test_bytes_that_are_no_leg_model_for_these_features_are_value_errors() -> None:
    forest, _ = _forest()
    with pytest.raises(ValueError, match=r"^not a leg model"):
        LegModel.from_bytes(b"not a zip at all")
    names = tuple(f"f{i}" for i in range(len(FEATURE_NAMES)))
    other = LegModel.from_forest(forest, names, {}).to_bytes()
    with pytest.raises(ValueError, match=r"^the leg model was trained on features f0, f1"):
        LegModel.from_bytes(other, FEATURE_NAMES)


def test_pairing_matches_closest_legs_and_keeps_confident_singles() -> None:
    xy = np.array([[0.0, 0.0], [0.25, 0.0], [0.4, 0.05], [3.0, 0.0], [6.0, 0.0]])
    prob = np.array([0.9, 0.9, 0.9, 0.95, 0.6])
    groups = pair_legs(xy, prob, LegParams(pair_distance=0.6, single_leg_probability=0.8))
    assert (1, 2) in groups  # the closest pair first
    assert (0,) in groups and (3,) in groups  # left alone, confident
    assert all(4 not in g for g in groups)  # alone and not confident


def test_labels_by_positions_and_scores() -> None:
    centroids = np.array([[1.0, 0.0], [1.2, 0.0], [3.0, 0.0]])
    lab = label_by_positions(centroids, np.array([[1.02, 0.0]]))
    assert lab.tolist() == [1, -1, 0]  # the piece next to a labelled leg is left out
    s = score(np.array([1, 1, 0, 0]), np.array([0.9, 0.2, 0.7, 0.1]), 0.5)
    assert (s.tp, s.fp, s.fn) == (1, 1, 1)
    assert s.precision == 0.5 and s.recall == 0.5


def test_train_forest_gives_a_small_model_with_metadata() -> None:
    rng = np.random.default_rng(1)
    data = LegDataset("toy")
    x = rng.normal(size=(300, len(FEATURE_NAMES)))
    data.add("a", x, (x[:, 1] > 0).astype(np.int8))
    model = train_forest(data, seed=3, n_trees=5, max_depth=4)
    assert model.n_trees == 5 and model.depth <= 4
    assert model.metadata["seed"] == 3 and model.metadata["segments"] == 300
    assert ((model.predict_proba(x) >= 0.5) == (x[:, 1] > 0)).mean() > 0.9


def _room_scan(seed: int, stamp: float = 0.0) -> LaserScan:
    """A 270° scan at 0.25° (1 cm noise) of a room: walls 3–5 m off, a box with a 1.2–1.3 m
    face, and three to six legs (6 cm radius) 0.8–3 m away, placed at random by ``seed``."""
    rng = np.random.default_rng(seed)
    angles = np.radians(np.arange(-135, 135.01, 0.25))
    d = np.array([np.cos(angles), np.sin(angles)])
    r = 4.0 + np.sin(2 * angles + rng.uniform(0, 6)) * 0.8
    box = (angles > 0.3) & (angles < 0.3 + 1.2 / 2.0)  # a flat face 2 m away
    r[box] = 2.0 / np.cos(angles[box] - 0.6)
    for _ in range(int(rng.integers(3, 7))):
        rho, phi = rng.uniform(0.8, 3.0), rng.uniform(-2.0, 2.0)
        cx, cy = rho * math.cos(phi), rho * math.sin(phi)
        b = -(d[0] * cx + d[1] * cy)
        disc = b**2 - (cx**2 + cy**2 - 0.06**2)
        hit = disc >= 0
        r[hit] = np.minimum(r[hit], -b[hit] - np.sqrt(disc[hit]))
    r = r + rng.normal(0, 0.01, len(r))
    return LaserScan(
        stamp, float(angles[0]), float(np.radians(0.25)), 0.05, 20.0, r, Pose2D(0.5, 0.2, 0.3)
    )


def test_shape_features_of_some_segments_are_theirs_among_all() -> None:
    segs = segment_scan(_room_scan(0).ranges, -2.356, 0.00436, 0.05, 20.0, 0.13)
    some = np.arange(0, len(segs), 3)
    whole, part = segment_features(segs), segment_features(segs, shape=some)
    np.testing.assert_array_equal(part[some], whole[some])
    rest = np.setdiff1d(np.arange(len(segs)), some)
    shape = [F[n] for n in ("std_centroid", "linearity", "radius", "mean_curvature")]
    assert np.all(part[np.ix_(rest, shape)] == 0)
    outline = [F[n] for n in ("points", "jump_preceding", "width", "distance", "neighbours")]
    np.testing.assert_array_equal(part[:, outline], whole[:, outline])
    # Several scans segmented and described in one pass: each as alone.
    scans = [_room_scan(k, 0.025 * k) for k in range(3)]
    joined = segment_scans(scans, 0.13)
    feats = segment_features(joined)
    parts = joined.split(len(scans))
    assert [len(p[1]) for p in parts] == np.bincount(joined.scan).tolist()
    for scan, (rows, segs) in zip(scans, parts, strict=True):
        alone = segment_scan(
            scan.ranges, scan.angle_min, scan.angle_increment, scan.range_min, 20.0, 0.13
        )
        for name in ("xy", "beam", "start", "count"):
            np.testing.assert_array_equal(getattr(segs, name), getattr(alone, name))
        np.testing.assert_array_equal(feats[rows], segment_features(alone))


def test_a_ticks_scans_classified_in_one_pass_are_classified_as_each_alone() -> None:
    model, params = load_leg_model(None), LegParams()
    scans = [_room_scan(seed, 0.025 * seed) for seed in range(4)]
    for alone, together in zip(
        [classify_segments(s, model, params) for s in scans],
        classify_scans(scans, model, params),
        strict=True,
    ):
        np.testing.assert_array_equal(together.classified, alone.classified)
        np.testing.assert_array_equal(together.features, alone.features)
        np.testing.assert_allclose(together.probability, alone.probability, rtol=0, atol=1e-12)
    # The detector given them finds what it finds alone, scan after scan (its history too).
    one, batched = LegDetector(model, params), LegDetector(model, params)
    legs = 0
    for scan, c in zip(scans, batched.classify(scans), strict=True):
        a, b = one.detect(scan), batched.detect(scan, classified=c)
        assert b == a
        legs += len(a.legs)
    assert legs >= 8  # the scans hold 3-6 legs each, most of them found


def test_segments_wider_than_max_width_are_not_classified() -> None:
    scan = _room_scan(0)
    segs, feats, ok = describe_segments(scan, LegParams())
    box = int(np.argmin(np.abs(feats[:, F["width"]] - 1.2) + (segs.count < 20)))
    assert 1.0 < feats[box, F["width"]] < 1.5
    assert not ok[box] and feats[box, F["linearity"]] == 0.0  # no shape features computed
    _, wide_feats, wide_ok = describe_segments(scan, LegParams(max_width=2.0))
    assert wide_ok[box] and wide_feats[box, F["linearity"]] > 0.0
