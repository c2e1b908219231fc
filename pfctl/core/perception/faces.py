"""Faces for target identification (Algorithm 2, §II-E): detect, align and embed with dlib.

The paper identifies the target by face first. A face is found with dlib's HOG frontal face
detector (``dlib.get_frontal_face_detector()``, Dalal & Triggs 2005 features, King 2009), aligned
with the 5-point landmark model and turned into a 128-D embedding by dlib's ResNet face
recognition model (King 2017, the models of ``face_recognition_models``). Two faces are the same
person when the Euclidean distance of their embeddings is below a threshold (0.6 is dlib's
operating point: 99.38 % on LFW; the mission's ``perception.identity.face_distance``).

The detector's sliding window is 80x80 pixels; each pyramid upsampling halves the smallest face
it finds. A robot's camera sees a head of ~30 px at 1.5 m (320x240, 58°), so :meth:`FaceEncoder.
detect` crops the head region a person detector gives and scales it so the head is
:attr:`FaceParams.head_px` pixels wide before detecting (that is what makes such faces
detectable), then maps the boxes back to the image.

The three models are loaded once, lazily, on first use (about 0.1 s; dlib and the model files
are imported only then).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: Length of a face embedding.
EMBEDDING_SIZE = 128

Box = tuple[int, int, int, int]
"""An image box ``(x0, y0, x1, y1)`` in pixels, ``x1``/``y1`` exclusive."""


@dataclass(frozen=True)
class FaceParams:
    """How faces are searched for."""

    upsample: int = 1
    """Pyramid upsamplings of dlib's detector (each finds faces half as small)."""
    head_px: int = 100
    """A head region is scaled (up or down) to this width before detection; 0: never."""
    jitters: int = 0
    """Random re-crops averaged per embedding (dlib's ``num_jitters``; 0: one pass)."""
    min_score: float = 0.0
    """Detections scoring below this (dlib's SVM margin) are dropped."""


@dataclass(frozen=True)
class Face:
    """One detected face: its box in the image, the detector's score and its embedding."""

    box: Box
    score: float
    embedding: np.ndarray
    """``(128,)`` float64, dlib's face descriptor (unit-ish norm)."""


@functools.cache
def _models() -> tuple[Any, Any, Any]:
    """dlib's detector, 5-point shape predictor and ResNet encoder, loaded once."""
    import dlib
    import face_recognition_models as frm

    return (
        dlib.get_frontal_face_detector(),
        dlib.shape_predictor(frm.pose_predictor_five_point_model_location()),
        dlib.face_recognition_model_v1(frm.face_recognition_model_location()),
    )


def face_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray | float:
    """Euclidean distance between embeddings: ``(128,)`` vs ``(128,)`` → float, or each row of
    ``(k, 128)`` against ``(128,)`` → ``(k,)``."""
    d = np.linalg.norm(np.asarray(a, dtype=float) - np.asarray(b, dtype=float), axis=-1)
    return float(d) if np.ndim(d) == 0 else d


class FaceEncoder:
    """Finds faces in RGB images and embeds them (dlib HOG detector + ResNet embeddings)."""

    def __init__(self, params: FaceParams | None = None) -> None:
        self.params = params or FaceParams()

    def detect(self, rgb: np.ndarray, region: Box | None = None) -> list[Face]:
        """Faces in ``rgb`` ``(h, w, 3) uint8``, or only inside ``region`` (e.g. a head box), best
        first. Boxes are in the full image's pixels."""
        detector, predictor, encoder = _models()
        h, w = rgb.shape[:2]
        x0, y0, x1, y1 = (0, 0, w, h) if region is None else region
        x0, y0 = max(0, int(x0)), max(0, int(y0))
        x1, y1 = min(w, int(x1)), min(h, int(y1))
        if x1 - x0 < 4 or y1 - y0 < 4:
            return []
        crop = np.ascontiguousarray(rgb[y0:y1, x0:x1, :3], dtype=np.uint8)
        scale = 1.0
        if region is not None and self.params.head_px > 0:
            scale = self.params.head_px / (x1 - x0)
            import cv2

            size = (max(1, round((x1 - x0) * scale)), max(1, round((y1 - y0) * scale)))
            interp = cv2.INTER_CUBIC if scale > 1 else cv2.INTER_AREA
            crop = cv2.resize(crop, size, interpolation=interp)
        rects, scores, _ = detector.run(crop, self.params.upsample, 0.0)
        out = []
        for rect, score in zip(rects, scores, strict=True):
            if score < self.params.min_score:
                continue
            shape = predictor(crop, rect)
            emb = np.array(encoder.compute_face_descriptor(crop, shape, self.params.jitters))
            box = (
                x0 + math.floor(rect.left() / scale),
                y0 + math.floor(rect.top() / scale),
                x0 + math.ceil((rect.right() + 1) / scale),
                y0 + math.ceil((rect.bottom() + 1) / scale),
            )
            out.append(Face(box, float(score), emb))
        return sorted(out, key=lambda f: -f.score)


__all__ = ["EMBEDDING_SIZE", "Box", "Face", "FaceEncoder", "FaceParams", "face_distance"]
