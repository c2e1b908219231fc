"""dlib faces (Algorithm 2's first filter): real photographs, real models, no mocks."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from skimage.data import astronaut, lfw_subset

from pfctl.core.perception.faces import EMBEDDING_SIZE, FaceEncoder, FaceParams, face_distance


@pytest.fixture(scope="module")
def encoder() -> FaceEncoder:
    return FaceEncoder(FaceParams(upsample=1))


@pytest.fixture(scope="module")
def eileen(encoder: FaceEncoder) -> np.ndarray:
    faces = encoder.detect(astronaut())  # best first
    x0, y0, x1, y1 = faces[0].box
    assert 160 < x0 < 190 and 250 < x1 < 280 and 60 < y0 < 90 and 150 < y1 < 180
    assert faces[0].embedding.shape == (EMBEDDING_SIZE,)
    return faces[0].embedding


def _lfw_rgb(index: int, size: int = 200) -> np.ndarray:
    gray = (lfw_subset()[index] * 255).astype(np.uint8)
    return np.dstack([cv2.resize(gray, (size, size), interpolation=cv2.INTER_CUBIC)] * 3)


def test_a_photo_matches_a_shifted_and_rescaled_copy_of_itself(
    encoder: FaceEncoder, eileen: np.ndarray
) -> None:
    img = astronaut()
    shifted = np.zeros_like(img)
    shifted[40:, 60:] = img[:-40, :-60]  # the face moves 60 px right and 40 px down
    small = cv2.resize(img, None, fx=0.6, fy=0.6, interpolation=cv2.INTER_AREA)
    for copy in (shifted, small):
        faces = encoder.detect(copy)
        assert face_distance(faces[0].embedding, eileen) < 0.3


def test_a_photo_does_not_match_other_faces(encoder: FaceEncoder, eileen: np.ndarray) -> None:
    for index in (0, 5, 20):  # three LFW faces (men, and the first is not Eileen Collins)
        faces = encoder.detect(_lfw_rgb(index))
        assert len(faces) == 1
        assert face_distance(faces[0].embedding, eileen) > 0.6


def test_a_small_face_is_found_in_its_head_region_and_boxed_in_image_pixels(
    encoder: FaceEncoder,
) -> None:
    """A ~36 px face in a 320x240 frame (a head at ~1.5 m): dlib's 80 px window misses it at
    the frame's own scale; scaling the head region up finds it."""
    face = _lfw_rgb(20, size=36)
    frame = np.full((240, 320, 3), 90, np.uint8)
    frame[50:86, 150:186] = face
    region = (140, 40, 196, 96)
    assert not FaceEncoder(FaceParams(upsample=0, head_px=0)).detect(frame, region)
    found = encoder.detect(frame, region)
    assert len(found) == 1
    x0, y0, x1, y1 = found[0].box
    assert 140 <= x0 < 165 and 170 < x1 <= 196 and 40 <= y0 < 65 and 72 < y1 <= 96
    whole = encoder.detect(_lfw_rgb(20))[0].embedding
    assert face_distance(found[0].embedding, whole) < 0.6


def test_face_distance_of_rows() -> None:
    a = np.zeros(EMBEDDING_SIZE)
    rows = np.stack([a, a + 0.1])
    d = face_distance(rows, a)
    assert isinstance(d, np.ndarray) and d.shape == (2,)
    assert d[0] == 0.0 and d[1] == pytest.approx(0.1 * np.sqrt(EMBEDDING_SIZE))
    assert isinstance(face_distance(a, a), float)
