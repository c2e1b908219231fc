"""Algorithm 2: clothes histograms, the target profile file, and per-track decisions over time.

The decisions are tested end to end on synthetic pictures of people (shirt, trousers, and a real
LFW face or the back of a head) through the real dlib models.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from skimage.data import lfw_subset

from pfctl.core.clothes import (
    ClothesParams,
    body_parts,
    color_histogram,
    histogram_intersection,
)
from pfctl.core.faces import FaceEncoder
from pfctl.core.identity import (
    PROFILE_VERSION,
    Decision,
    IdentityParams,
    TargetIdentifier,
    TargetProfile,
    describe,
    learn_profile,
)
from pfctl.core.vision import PersonDetection
from pfctl.errors import UserError

RED, GREEN, NAVY, GREY = (200, 30, 40), (30, 160, 60), (40, 40, 120), (90, 90, 90)
TARGET_FACE, OTHER_FACE = 20, 77  # two LFW faces far apart in dlib's embedding space


def test_histogram_intersection_with_itself_is_one_and_with_a_disjoint_one_zero() -> None:
    rng = np.random.default_rng(0)
    h = rng.random(64)
    h /= h.sum()
    assert histogram_intersection(h, h) == pytest.approx(1.0)
    a, b = np.zeros(64), np.zeros(64)
    a[:32], b[32:] = 1 / 32, 1 / 32
    assert histogram_intersection(a, b) == 0.0
    # normalised by the target's mass: S(I, T) = Σ min / Σ T
    assert histogram_intersection(a / 2, a) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="size"):
        histogram_intersection(a, np.ones(3))


def test_color_histograms_are_normalised_and_separate_colours() -> None:
    params = ClothesParams("hsv", (16, 4, 4))
    img = np.zeros((20, 20, 3), np.uint8)
    img[:10], img[10:] = RED, GREEN
    top, bottom = np.zeros((20, 20), bool), np.zeros((20, 20), bool)
    top[:10], bottom[10:] = True, True
    ht, hb = color_histogram(img, top, params), color_histogram(img, bottom, params)
    assert ht is not None and hb is not None
    assert ht.shape == (params.size,) and ht.sum() == pytest.approx(1.0)
    assert histogram_intersection(ht, hb) == 0.0
    assert color_histogram(img, np.zeros((20, 20), bool), params) is None
    for space in ("rgb", "lab"):
        h = color_histogram(img, top, ClothesParams(space, (8, 8, 8)))  # type: ignore[arg-type]
        assert h is not None and h.sum() == pytest.approx(1.0)


def test_body_split_uses_keypoints_else_fixed_fractions_of_the_box() -> None:
    shape, box = (200, 100), (20, 0, 80, 200)
    upper, lower = body_parts(shape, box)
    rows_u, rows_l = np.nonzero(upper.any(axis=1))[0], np.nonzero(lower.any(axis=1))[0]
    assert (rows_u.min(), rows_u.max()) == (40, 95)  # 20..48 % of 200 rows
    assert (rows_l.min(), rows_l.max()) == (110, 189)  # 55..95 %
    assert not upper[:, :35].any() and upper[:, 35:65].all(axis=1).any()  # the central half
    kp = {"neck": (50.0, 50.0), "mid_hip": (50.0, 150.0), "ankles": (50.0, 190.0)}
    upper, lower = body_parts(shape, box, keypoints=kp)
    rows_u, rows_l = np.nonzero(upper.any(axis=1))[0], np.nonzero(lower.any(axis=1))[0]
    assert 50 <= rows_u.min() <= 55 and 145 <= rows_u.max() < 150
    assert 150 < rows_l.min() <= 155 and rows_l.max() == 189


def _profile(faces: int = 2) -> TargetProfile:
    rng = np.random.default_rng(1)
    upper, lower = rng.random(256), rng.random(256)
    return TargetProfile(
        upper / upper.sum(), lower / lower.sum(), rng.normal(size=(faces, 128)), frames=7
    )


def test_profile_round_trips_through_npz_and_bad_files_are_user_errors(tmp_path) -> None:
    prof = _profile()
    path = prof.save(tmp_path / "t.npz")
    back = TargetProfile.load(path)
    assert np.array_equal(back.upper, prof.upper) and np.array_equal(back.faces, prof.faces)
    assert (back.color_space, back.bins, back.frames) == ("hsv", (16, 4, 4), 7)
    assert TargetProfile.load(_profile(0).save(tmp_path / "noface.npz")).faces.shape == (0, 128)
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    np.savez(tmp_path / "old.npz", **{**_fields(prof), "version": np.array(PROFILE_VERSION + 1)})
    np.savez(tmp_path / "bins.npz", **{**_fields(prof), "bins": np.array([8, 4, 4])})
    np.savez(tmp_path / "part.npz", upper=prof.upper)
    obj = np.array([{"evil": 1}], dtype=object)
    np.savez(tmp_path / "pickle.npz", **{**_fields(prof), "faces": obj})
    cases = {
        "missing.npz": "no such",
        "junk.npz": "not a target profile",
        "old.npz": "version",
        "bins.npz": "upper",
        "part.npz": "missing",
        "pickle.npz": "not a target profile",
    }
    for name, words in cases.items():
        with pytest.raises(UserError, match=words) as err:
            TargetProfile.load(tmp_path / name)
        assert name in str(err.value) and "\n" not in str(err.value)


def _fields(prof: TargetProfile) -> dict[str, np.ndarray]:
    with np.load(__import__("io").BytesIO(prof.to_bytes())) as data:
        return {k: data[k] for k in data.files}


def test_a_profile_in_other_bins_than_the_mission_is_refused() -> None:
    params = IdentityParams(clothes=ClothesParams("rgb", (8, 8, 8)))
    with pytest.raises(UserError, match="learn it again"):
        TargetIdentifier(_profile(), params)


# -- decisions over time, on pictures through the real dlib models ----------------------------


def _picture(shirt, face: int | None) -> tuple[np.ndarray, PersonDetection]:
    """A 240x160 picture of a person: head 60x72 px (an LFW face, or the back of the head when
    ``face`` is None), shirt and navy trousers; the detection an OpenPose source would give."""
    img = np.full((240, 160, 3), GREY, np.uint8)
    if face is None:
        img[4:76, 50:110] = (60, 40, 30)  # hair
    else:
        gray = (lfw_subset()[face] * 255).astype(np.uint8)
        img[4:76, 50:110] = np.dstack([cv2.resize(gray, (60, 72), cv2.INTER_CUBIC)] * 3)
    img[80:150, 30:130] = shirt
    img[150:236, 40:120] = NAVY
    kp = {"neck": (80.0, 80.0), "mid_hip": (80.0, 150.0), "ankles": (80.0, 236.0)}
    det = PersonDetection(
        (30, 4, 130, 236), (2.0, 0.0, 1.0), keypoints=kp, head_box=(50, 4, 110, 76)
    )
    return img, det


@pytest.fixture(scope="module")
def learned() -> tuple[TargetProfile, IdentityParams, FaceEncoder]:
    params = IdentityParams()
    encoder = FaceEncoder(params.face)
    views = [_picture(RED, TARGET_FACE), _picture(RED, None)]
    profile = learn_profile([describe(img, det, params, encoder) for img, det in views], params)
    assert len(profile.faces) == 1
    return profile, params, encoder


def test_a_face_match_carries_the_track_through_back_views(learned) -> None:
    profile, params, encoder = learned
    ident = TargetIdentifier(profile, params, encoder)
    first = ident.observe(1, 0.0, True, *reversed(_picture(RED, TARGET_FACE)))
    assert first.decision is Decision.TARGET and first.basis == "face"
    assert first.face_distance is not None and first.face_distance < 0.3
    for k in range(1, 4):  # the target turns around: no face any more
        later = ident.observe(1, 0.1 * k, True, *reversed(_picture(RED, None)))
        assert later.decision is Decision.TARGET and later.basis == "face"
    assert later.face_samples == 1 and later.clothes_samples == 4 and later.observations == 4
    assert ident.target_track() == 1


def test_a_mismatching_face_stays_rejected_even_when_the_clothes_match(learned) -> None:
    profile, params, encoder = learned
    ident = TargetIdentifier(profile, params, encoder)
    seen = ident.observe(2, 0.0, True, *reversed(_picture(RED, OTHER_FACE)))
    assert seen.decision is Decision.NOT_TARGET and seen.basis == "face"
    assert seen.clothes_similarity is not None and seen.clothes_similarity > 0.9
    for k in range(1, 4):
        later = ident.observe(2, 0.1 * k, True, *reversed(_picture(RED, None)))
        assert later.decision is Decision.NOT_TARGET
    # a look-alike seen only from behind is the target by its clothes, until a face decides
    back = ident.observe(3, 0.5, True, *reversed(_picture(RED, None)))
    assert back.decision is Decision.TARGET and back.basis == "clothes"
    assert ident.target_track() == 3
    green = ident.observe(4, 0.5, True, *reversed(_picture(GREEN, None)))
    assert green.decision is Decision.NOT_TARGET and green.basis == "clothes"
    # the true target's face outranks clothes alone
    ident.observe(5, 0.6, True, *reversed(_picture(RED, TARGET_FACE)))
    assert ident.target_track() == 5
    ident.forget(5)
    assert ident.identity(5) is None and ident.target_track() == 3


def test_tracks_without_legs_are_not_candidates_and_unseen_tracks_keep_their_evidence(
    learned,
) -> None:
    profile, params, encoder = learned
    ident = TargetIdentifier(profile, params, encoder)
    no_legs = ident.observe(7, 0.0, False, *reversed(_picture(RED, TARGET_FACE)))
    assert no_legs.decision is Decision.UNKNOWN and no_legs.basis == "no_legs"
    assert ident.target_track() is None
    legs = ident.observe(7, 0.1, True, None, None)  # legs now; the camera did not see it
    assert legs.decision is Decision.TARGET and legs.face_samples == 1
    assert ident.observe(8, 0.1, True, None, None).decision is Decision.UNKNOWN
