"""Person detection on the RGB-D camera with 3-D positions (§II-E).

On the HSR the paper detects people with OpenPose and places each in 3-D from the depth of its
body. Here a detector is anything with ``detect(frame) -> list[PersonDetection]``
(:class:`PersonDetector`); three implementations:

- :class:`MaskPersonDetector`: the simulator's, from its segmentation mask. It **stands in for
  OpenPose**: it is told which body ids belong to which person instance (and, optionally, which
  part each body is) by the backend, so core never imports pybullet.
- :class:`HogPersonDetector`: OpenCV's built-in HOG + linear SVM people detector (Dalal & Triggs
  2005, ``cv2.HOGDescriptor_getDefaultPeopleDetector``, nothing to download) for real cameras,
  with non-maximum suppression.
- :class:`GivenPersonDetector`: wraps boxes / keypoints from an external pose source (e.g.
  OpenPose over ROS on the real robot, carried on the frame as ``RgbdFrame.people``) and adds
  the 3-D positions (from the depth around the torso keypoints when there are some).

The 3-D position (:func:`body_position`) is robust: the median of the map-frame 3-D points of
the body pixels with a valid depth (back-projected with the intrinsics, through the frame's
camera pose), pushed :data:`BODY_HALF_DEPTH` further along the horizontal line of sight because
the camera sees the front of the body and the tracker wants its centre.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal, Protocol, runtime_checkable

import numpy as np

from pfctl.core.perception.faces import Box
from pfctl.core.robot import GivenPerson, RgbdFrame

#: Half the front-to-back depth of a person's body, metres: a surface point's offset from the
#: body's centre along the line of sight.
BODY_HALF_DEPTH = 0.1

#: Body part names a backend may give the mask detector, and their codes.
_PARTS = {"head": 1, "torso": 2, "leg": 3}

Keypoints = Mapping[str, tuple[float, float]]
"""2-D keypoints ``name -> (u, v)`` in pixels. Names used here (OpenPose BODY_25 spirit):
``head`` (centre of the head), ``neck``, ``mid_hip``, ``ankles`` (mid-point of the feet); a
pose estimator may add ``right_shoulder``, ``left_shoulder``, ``right_hip`` and ``left_hip``
(BODY_25 2, 5, 9, 12), which :class:`GivenPersonDetector` measures the depth around."""

TORSO_KEYPOINTS = ("neck", "right_shoulder", "left_shoulder", "mid_hip", "right_hip", "left_hip")
"""The keypoints on the torso: a given person's depth is read around them (and their centre)."""


@dataclass(frozen=True)
class PersonDetection:
    """One person seen in one RGB-D frame."""

    box: Box
    """Image box ``(x0, y0, x1, y1)`` of the whole body, pixels (``x1``, ``y1`` exclusive)."""
    position: tuple[float, float, float]
    """The body's centre in the map frame, metres, from the depth of its pixels."""
    score: float = 1.0
    """Detector confidence (HOG: the SVM margin; mask: 1)."""
    mask: np.ndarray | None = None
    """``(h, w) bool`` body pixels, when the detector segments."""
    keypoints: Keypoints | None = None
    """2-D keypoints, when known (see :data:`Keypoints`)."""
    head_box: Box | None = None
    """Where the head is, when the detector knows (faces are searched there)."""
    instance: int | None = None
    """The detector's own index of the person (simulator instance), never a name."""
    ground_truth_name: str | None = field(default=None, compare=False)
    """GROUND TRUTH (simulator, tests and metrics only): never for the follower's decisions."""


@runtime_checkable
class PersonDetector(Protocol):
    """Finds people in an RGB-D frame (OpenPose on the HSR, §II-E)."""

    def detect(self, frame: RgbdFrame) -> list[PersonDetection]:
        """The people in ``frame`` with their 3-D positions."""
        ...


def horizontal_range(frame: RgbdFrame, detection: PersonDetection) -> float:
    """Horizontal distance from the camera to the detection, metres."""
    cx, cy, _ = frame.camera_position
    return math.hypot(detection.position[0] - cx, detection.position[1] - cy)


def pixels_to_map(frame: RgbdFrame, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """Back-project pixels ``(u, v)`` with their depth to map-frame points ``(n, 3)``; pixels
    without a finite depth are dropped."""
    return _to_map(frame, frame.depth[vs, us], us, vs)


def _to_map(frame: RgbdFrame, depth: np.ndarray, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """:func:`pixels_to_map` of the pixels ``(us, vs)`` whose depths are ``depth``: the camera
    coordinates ``((u − cx) z / fx, (v − cy) z / fy, z)`` written into one ``(n, 3)`` array
    (no column stacking) and moved into the map frame in place, the same numbers."""
    z = depth.astype(float)
    ok = np.isfinite(z) & (z > 0)
    if not ok.all():
        z, us, vs = z[ok], us[ok], vs[ok]
    info = frame.info
    cam = np.empty((len(z), 3))
    for col, pix, c, f in ((0, us, info.cx, info.fx), (1, vs, info.cy, info.fy)):
        out = cam[:, col]
        np.subtract(pix.astype(float), c, out=out)
        out *= z
        out /= f
    cam[:, 2] = z
    pts = cam @ np.asarray(frame.camera_rotation, dtype=float).T
    for col, offset in enumerate(np.asarray(frame.camera_position, dtype=float)):
        pts[:, col] += offset  # one column at a time: faster than broadcasting over rows of 3
    return pts


def _median_columns(pts: np.ndarray) -> tuple[float, float, float]:
    """``numpy.median(pts, axis=0)`` of finite points ``(n ≥ 1, 3)``: per column the middle
    value, or the mean of the two middle values, found by one partition of that column alone
    (a contiguous copy), the same numbers in less time."""
    n = len(pts)
    m = n // 2
    out = []
    for j in range(3):
        c = np.ascontiguousarray(pts[:, j])
        if n % 2:
            c.partition(m)
            out.append(float(c[m]))
        else:
            c.partition((m - 1, m))
            out.append(float(np.mean(c[m - 1 : m + 1])))
    return out[0], out[1], out[2]


def body_position(
    frame: RgbdFrame, us: np.ndarray, vs: np.ndarray, half_depth: float = BODY_HALF_DEPTH
) -> tuple[float, float, float] | None:
    """The body's centre in the map frame from its pixels: the per-axis median of their 3-D
    points, moved ``half_depth`` away from the camera horizontally; None if no pixel has depth."""
    return _body_position(frame, pixels_to_map(frame, us, vs), half_depth)


def _body_position(
    frame: RgbdFrame, pts: np.ndarray, half_depth: float = BODY_HALF_DEPTH
) -> tuple[float, float, float] | None:
    """:func:`body_position` of the body's map-frame points ``pts`` (``(n, 3)``)."""
    if len(pts) == 0:
        return None
    if np.isfinite(frame.camera_rotation).all() and np.isfinite(frame.camera_position).all():
        x, y, z = _median_columns(pts)  # finite depths and pose: finite points
    else:
        x, y, z = np.median(pts, axis=0)
    cx, cy, _ = frame.camera_position
    d = math.hypot(x - cx, y - cy)
    if d > 1e-6 and half_depth:
        x += half_depth * (x - cx) / d
        y += half_depth * (y - cy) / d
    return float(x), float(y), float(z)


def _int_median(values: np.ndarray) -> float:
    """``float(numpy.median(values))`` of non-negative integers (pixel columns): the middle
    value, or the mean of the two middle values, read off their counts (a bincount, not a
    partition); the same number, integers being exact in a float."""
    n = len(values)
    ends = np.cumsum(np.bincount(values))
    m = n // 2
    b = float(np.searchsorted(ends, m, side="right"))  # the value of rank m (from 0)
    if n % 2:
        return b
    a = float(np.searchsorted(ends, m - 1, side="right"))
    return (a + b) / 2


def _bbox(us: np.ndarray, vs: np.ndarray) -> Box:
    return int(us.min()), int(vs.min()), int(us.max()) + 1, int(vs.max()) + 1


class MaskPersonDetector:
    """People from the simulator's segmentation mask; **stands in for OpenPose**.

    ``instances`` maps each PyBullet body id that belongs to a person to that person's instance
    index (given by the backend; core does not import pybullet). ``parts`` (optional) names what
    each body is (``head``, ``torso``, ``leg``): then the detection has a ``head_box`` and the
    keypoints ``head``, ``neck``, ``mid_hip`` and ``ankles``, as a pose estimator would give.
    ``names`` (optional) adds the GROUND-TRUTH name to each detection, for tests only.
    A person with fewer than ``min_pixels`` visible pixels or no valid depth is not detected.
    """

    def __init__(
        self,
        instances: Mapping[int, int],
        parts: Mapping[int, str] | None = None,
        *,
        min_pixels: int = 150,
        names: Mapping[int, str] | None = None,
    ) -> None:
        self.instances = dict(instances)
        self.parts = dict(parts or {})
        self.min_pixels = int(min_pixels)
        self.names = dict(names or {})
        # Lookup tables indexed by body id: the person (index into ``_people``, -1: no person)
        # and the part code; ids outside [0, _top) read the last entry (no person).
        people = sorted(set(self.instances.values()))
        self._people = np.array(people, dtype=np.int64)
        self._top = max(self.instances, default=-1) + 1
        self._person = np.full(self._top + 1, -1, dtype=np.int16)
        self._part = np.zeros(self._top + 1, dtype=np.int8)
        for body, instance in self.instances.items():
            if body < 0:
                raise ValueError(f"body ids must be ≥ 0, got {body}")
            self._person[body] = people.index(instance)
            self._part[body] = _PARTS.get(self.parts.get(body, ""), 0)

    def detect(self, frame: RgbdFrame) -> list[PersonDetection]:
        """One detection per person instance with at least ``min_pixels`` pixels, by instance
        (the people OpenPose would give the paper's §II-E).

        One pass over the mask: body id → person and part through lookup tables, a pixel
        count per person (bincount), and one stable sort of the people's pixels by person, so
        each person's pixels come out in row-major order, as ``numpy.nonzero`` of its mask
        would give them.
        """
        if frame.mask is None:
            raise ValueError("MaskPersonDetector needs a frame with a segmentation mask")
        mask = frame.mask
        if len(self._people) == 0:
            return []
        h, w = mask.shape
        flat = mask.ravel()
        if flat.dtype.kind not in "iu":
            flat = flat.astype(np.int64)
        # negative ids become huge unsigned ones: both end on the "no person" entry
        code = np.minimum(flat.view(flat.dtype.str.replace("i", "u")), self._top)
        person = np.take(self._person, code)
        pixels = np.flatnonzero(person >= 0)
        if not len(pixels):
            return []
        who = person[pixels]
        counts = np.bincount(who, minlength=len(self._people))
        pixels = pixels[np.argsort(who, kind="stable")]
        parts = self._part[code[pixels]] if self.parts else None
        ends = np.cumsum(counts)
        # flat indices read the depth faster than (v, u) pairs
        depth = frame.depth.ravel() if frame.depth.shape == mask.shape else None
        out = []
        for i, instance in enumerate(self._people):
            if counts[i] < max(self.min_pixels, 1):
                continue
            span = slice(int(ends[i] - counts[i]), int(ends[i]))
            idx = pixels[span]
            vs, us = np.divmod(idx, w)
            z = depth[idx] if depth is not None else frame.depth[vs, us]
            position = _body_position(frame, _to_map(frame, z, us, vs))
            if position is None:
                continue
            body = np.zeros(h * w, dtype=bool)
            body[idx] = True
            head_box, keypoints = (
                self._parts_of(parts[span], us, vs) if parts is not None else (None, None)
            )
            out.append(
                PersonDetection(
                    box=_bbox(us, vs),
                    position=position,
                    score=1.0,
                    mask=body.reshape(h, w),
                    keypoints=keypoints,
                    head_box=head_box,
                    instance=int(instance),
                    ground_truth_name=self.names.get(int(instance)),
                )
            )
        return out

    @staticmethod
    def _parts_of(
        part: np.ndarray, us: np.ndarray, vs: np.ndarray
    ) -> tuple[Box | None, Keypoints | None]:
        """The head box and keypoints from the part code of each of a person's pixels."""
        pix: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for name, code in _PARTS.items():
            sel = part == code
            if sel.any():
                pix[name] = (us[sel], vs[sel])
        keypoints: dict[str, tuple[float, float]] = {}
        head_box = None
        if "head" in pix:
            us, vs = pix["head"]
            head_box = _bbox(us, vs)
            keypoints["head"] = (float(np.mean(us)), float(np.mean(vs)))
        if "torso" in pix:
            us, vs = pix["torso"]
            u = _int_median(us)
            keypoints["neck"] = (u, float(vs.min()))
            keypoints["mid_hip"] = (u, float(vs.max()))
        if "leg" in pix:
            us, vs = pix["leg"]
            keypoints["ankles"] = (_int_median(us), float(vs.max()))
        return head_box, keypoints or None


def non_max_suppression(boxes: np.ndarray, scores: np.ndarray, overlap: float) -> list[int]:
    """Indices of the boxes ``(n, 4)`` ``x0, y0, x1, y1`` kept, best first: a box is dropped when
    its intersection over union with a better kept box exceeds ``overlap``."""
    order = list(np.argsort(-np.asarray(scores, dtype=float)))
    keep: list[int] = []
    b = np.asarray(boxes, dtype=float)
    area = (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])
    while order:
        i = order.pop(0)
        keep.append(int(i))
        rest = []
        for j in order:
            w = min(b[i, 2], b[j, 2]) - max(b[i, 0], b[j, 0])
            h = min(b[i, 3], b[j, 3]) - max(b[i, 1], b[j, 1])
            inter = max(w, 0.0) * max(h, 0.0)
            if inter / (area[i] + area[j] - inter) <= overlap:
                rest.append(j)
        order = rest
    return keep


def central_pixels(box: Box, shape: tuple[int, int], fraction: float) -> tuple[np.ndarray, ...]:
    """Pixel coordinates ``(us, vs)`` of the central part of ``box`` (``fraction`` of its
    width and height), clipped to the image ``shape``."""
    x0, y0, x1, y1 = box
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    hw, hh = fraction * (x1 - x0) / 2, fraction * (y1 - y0) / 2
    h, w = shape
    u0, u1 = max(0, int(cx - hw)), min(w, math.ceil(cx + hw))
    v0, v1 = max(0, int(cy - hh)), min(h, math.ceil(cy + hh))
    vs, us = np.mgrid[v0:v1, u0:u1]
    return us.ravel(), vs.ravel()


def torso_pixels(
    keypoints: Keypoints, box: Box, shape: tuple[int, int], window: float = 0.03
) -> tuple[np.ndarray, np.ndarray] | None:
    """Pixel coordinates ``(us, vs)`` around a person's :data:`TORSO_KEYPOINTS` and their
    centre: a square of half-size ``window`` × the box's height (at least 2 px) around each,
    clipped to the image ``shape``; None when no torso keypoint is inside the image."""
    h, w = shape
    points = [keypoints[k] for k in TORSO_KEYPOINTS if k in keypoints]
    points = [(u, v) for u, v in points if 0 <= u < w and 0 <= v < h]
    if not points:
        return None
    if len(points) > 1:
        points.append(
            (sum(u for u, _ in points) / len(points), sum(v for _, v in points) / len(points))
        )
    r = max(2, round(window * (box[3] - box[1])))
    us, vs = [], []
    for u, v in points:
        cu, cv = int(u), int(v)
        u0, u1 = max(0, cu - r), min(w, cu + r + 1)
        v0, v1 = max(0, cv - r), min(h, cv + r + 1)
        grid_v, grid_u = np.mgrid[v0:v1, u0:u1]
        us.append(grid_u.ravel())
        vs.append(grid_v.ravel())
    return np.concatenate(us), np.concatenate(vs)


class GivenPersonDetector:
    """People from an external 2-D source (§II-E: OpenPose, whose detections the paper placed
    in 3-D with the depth image): the frame's own ``RgbdFrame.people`` when it has them (the HSR
    backend's ``person_keypoints`` topic, a replayed bag's), else the boxes and optional
    keypoints given for the next frame with :meth:`set`. :meth:`detect` adds the 3-D positions
    (:func:`body_position`'s conventions): from the depth around the torso keypoints
    (:func:`torso_pixels`: neck, shoulders, hips and their centre) when the person has some,
    else — or when none of those pixels has a depth — from the box's central part
    (``central_fraction`` of its width and height)."""

    def __init__(self, central_fraction: float = 0.4, torso_window: float = 0.03) -> None:
        self.central_fraction = central_fraction
        self.torso_window = torso_window
        self._given: list[GivenPerson] = []

    def set(self, people: Sequence[tuple[Box, Keypoints | None, float] | GivenPerson]) -> None:
        """The people of the next frame (used when the frame carries none of its own):
        :class:`~pfctl.core.robot.GivenPerson` or ``(box, keypoints or None, score)`` each."""
        self._given = [
            p if isinstance(p, GivenPerson) else GivenPerson(p[0], p[1], float(p[2]))
            for p in people
        ]

    def position(self, frame: RgbdFrame, person: GivenPerson) -> tuple[float, float, float] | None:
        """The person's body centre in the map frame (class docstring), or None without depth."""
        shape = frame.depth.shape
        if person.keypoints:
            torso = torso_pixels(person.keypoints, person.box, shape, self.torso_window)
            if torso is not None:
                position = body_position(frame, *torso)
                if position is not None:
                    return position
        us, vs = central_pixels(person.box, shape, self.central_fraction)
        return body_position(frame, us, vs)

    def detect(self, frame: RgbdFrame) -> list[PersonDetection]:
        people = frame.people if frame.people is not None else self._given
        out = []
        for person in people:
            position = self.position(frame, person)
            if position is not None:
                out.append(
                    PersonDetection(
                        person.box,
                        position,
                        float(person.score),
                        keypoints=person.keypoints,
                        head_box=person.head_box,
                    )
                )
        return out


class DetectorUnavailableError(RuntimeError):
    """The person detector asked for cannot run with the installed libraries."""


def hog_available() -> bool:
    """Whether the installed OpenCV has the HOG people detector (OpenCV 4 does, 5.0 does not)."""
    import cv2

    return hasattr(cv2, "HOGDescriptor") and hasattr(cv2, "HOGDescriptor_getDefaultPeopleDetector")


class HogPersonDetector:
    """OpenCV's HOG people detector (Dalal & Triggs 2005; the default 64x128 linear SVM).

    The image is searched at ``upscale`` (small people in a 320x240 frame need it), boxes are
    merged by :func:`non_max_suppression`, and each box's position is the median depth of its
    central part (:data:`central_fraction` of width and height, the torso, not the background).
    """

    def __init__(
        self,
        *,
        hit_threshold: float = 0.0,
        upscale: float = 1.0,
        overlap: float = 0.4,
        central_fraction: float = 0.3,
        min_score: float = 0.3,
    ) -> None:
        import cv2

        if not hog_available():
            raise DetectorUnavailableError(
                f"OpenCV {cv2.__version__} has no HOG people detector (OpenCV 5 moved it out of "
                "the main package): install opencv-python-headless<5"
            )
        self._hog = cv2.HOGDescriptor()
        self._hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
        self.hit_threshold = hit_threshold
        self.upscale = upscale
        self.overlap = overlap
        self.central_fraction = central_fraction
        self.min_score = min_score

    def fits(self, shape: tuple[int, ...]) -> bool:
        """Whether an image of this shape (rows, columns, ...) holds the detector's window.

        Nobody smaller than the window can be found (the search only scales the image down), and
        OpenCV's ``detectMultiScale`` may crash the process (SIGSEGV) on a smaller image.
        """
        win_w, win_h = self._hog.winSize
        return shape[0] >= win_h and shape[1] >= win_w

    def boxes(self, rgb: np.ndarray) -> list[tuple[Box, float]]:
        """Person boxes in an RGB image with their SVM scores, after suppression, best first
        (none in an image smaller than the detector's window, see :meth:`fits`)."""
        import cv2

        img = rgb
        if self.upscale != 1.0:
            img = cv2.resize(rgb, None, fx=self.upscale, fy=self.upscale)
        if not self.fits(img.shape):
            return []
        rects, weights = self._hog.detectMultiScale(
            np.ascontiguousarray(img),
            hitThreshold=self.hit_threshold,
            winStride=(8, 8),
            padding=(8, 8),
            scale=1.05,
        )
        if len(rects) == 0:
            return []
        r = np.asarray(rects, dtype=float).reshape(-1, 4) / self.upscale
        scores = np.asarray(weights, dtype=float).ravel()
        boxes = np.column_stack((r[:, 0], r[:, 1], r[:, 0] + r[:, 2], r[:, 1] + r[:, 3]))
        out = []
        for i in non_max_suppression(boxes, scores, self.overlap):
            if scores[i] < self.min_score:
                continue
            b = boxes[i]
            out.append(((int(b[0]), int(b[1]), int(b[2]), int(b[3])), float(scores[i])))
        return out

    def detect(self, frame: RgbdFrame) -> list[PersonDetection]:
        out = []
        for box, score in self.boxes(frame.rgb):
            us, vs = central_pixels(box, frame.depth.shape, self.central_fraction)
            position = body_position(frame, us, vs)
            if position is not None:
                out.append(PersonDetection(box, position, score))
        return out


def make_detector(
    kind: Literal["auto", "mask", "hog"],
    frame: RgbdFrame | None = None,
    *,
    instances: Mapping[int, int] | None = None,
    parts: Mapping[int, str] | None = None,
    min_pixels: int = 150,
) -> PersonDetector:
    """The detector ``VisionConfig.detector`` asks for: ``auto`` is ``mask`` when ``frame`` has
    a segmentation mask and ``instances`` are known, else ``hog``. ``mask`` without
    ``instances`` is a ValueError."""
    if kind == "auto":
        has_mask = frame is not None and frame.mask is not None
        kind = "mask" if has_mask and instances is not None else "hog"
    if kind == "mask":
        if instances is None:
            raise ValueError("the mask detector needs the body id -> person instance mapping")
        return MaskPersonDetector(instances, parts, min_pixels=min_pixels)
    return HogPersonDetector()


__all__ = [
    "BODY_HALF_DEPTH",
    "TORSO_KEYPOINTS",
    "DetectorUnavailableError",
    "GivenPersonDetector",
    "HogPersonDetector",
    "Keypoints",
    "MaskPersonDetector",
    "PersonDetection",
    "PersonDetector",
    "body_position",
    "central_pixels",
    "hog_available",
    "horizontal_range",
    "make_detector",
    "non_max_suppression",
    "pixels_to_map",
    "torso_pixels",
]
