"""The target's appearance for Algorithm 2 (§II-E): what one frame shows of a person (clothes
histograms, a face), and the target's profile learned from such frames.

:class:`TargetProfile` is what ``pfctl learn-target`` learns: the target's upper and lower
clothing histograms and up to :data:`MAX_PROFILE_FACES` face embeddings, as the bytes of a
versioned ``.npz`` (no pickles). Reading and writing the files is the app's
(:mod:`pfctl.app.profiles`).
"""

from __future__ import annotations

import io
import math
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pfctl.core.perception.clothes import (
    ClothesParams,
    ColorSpace,
    body_parts_window,
    color_histograms,
    convert,
    histogram_intersection,
    relit_intersection,
)
from pfctl.core.perception.faces import (
    EMBEDDING_SIZE,
    Box,
    FaceEncoder,
    face_distance,
)
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.vision import PersonDetection

#: Version of the profile file format.
PROFILE_VERSION = 1
#: At most this many face embeddings are kept in a profile (spread over the samples).
MAX_PROFILE_FACES = 32
#: A head region narrower than this (pixels) is not searched for a face (too far).
MIN_HEAD_PX = 12


@dataclass(frozen=True)
class Appearance:
    """What one detection looks like: clothing histograms (None when that part was not seen)
    and the face embedding (None when no face was found)."""

    upper: np.ndarray | None
    lower: np.ndarray | None
    face: np.ndarray | None = None
    face_box: Box | None = None


def head_region(detection: PersonDetection) -> Box:
    """Where to look for the face: the detector's head box (widened by a quarter), else the top
    quarter of the body box's central 60 %."""
    if detection.head_box is not None:
        x0, y0, x1, y1 = detection.head_box
        mx, my = (x1 - x0) // 4 + 1, (y1 - y0) // 4 + 1
        return x0 - mx, y0 - my, x1 + mx, y1 + my
    x0, y0, x1, y1 = detection.box
    w, h = x1 - x0, y1 - y0
    return int(x0 + 0.2 * w), y0, math.ceil(x1 - 0.2 * w), int(y0 + 0.25 * h)


def _head_cut(detection: PersonDetection, shape: tuple[int, ...]) -> bool:
    """Whether the detector's head box touches the image border (a cut face embeds badly)."""
    if detection.head_box is None:
        return False
    x0, y0, x1, y1 = detection.head_box
    return x0 <= 0 or y0 <= 0 or x1 >= shape[1] or y1 >= shape[0]


def face_region(detection: PersonDetection, shape: tuple[int, ...]) -> Box | None:
    """The :func:`head_region` to search for the detection's face in an image of ``shape``, or
    None when it is not worth searching: the head box touches the border (a cut face embeds
    badly) or the region is narrower than :data:`MIN_HEAD_PX`."""
    if _head_cut(detection, shape):
        return None
    region = head_region(detection)
    return region if region[2] - region[0] >= MIN_HEAD_PX else None


def describe(
    rgb: np.ndarray,
    detection: PersonDetection,
    params: IdentityParams,
    encoder: FaceEncoder | None = None,
    converted: np.ndarray | None = None,
) -> Appearance:
    """Measure a detection in ``rgb``: its upper/lower histograms and, with ``encoder``, its
    best face inside :func:`head_region` (not when the head box touches the image border: a cut
    face embeds badly). ``converted`` is ``rgb`` already in the clothes'
    colour space (to convert once per frame for several people)."""
    shape = rgb.shape[:2]
    (r0, r1, c0, c1), upper_mask, lower_mask = body_parts_window(
        shape, detection.box, detection.mask, dict(detection.keypoints or {})
    )
    # the person's box: the same pixels as the whole image's masks
    if converted is not None:
        img = converted[r0:r1, c0:c1]
    else:
        img = convert(rgb[r0:r1, c0:c1], params.clothes.color_space)
    upper, lower = color_histograms(img, (upper_mask, lower_mask), params.clothes, converted=True)
    face = face_box = None
    region = face_region(detection, shape) if encoder is not None and params.faces else None
    if encoder is not None and region is not None:
        faces = encoder.detect(rgb, region)
        if faces:
            face, face_box = faces[0].embedding, faces[0].box
    return Appearance(upper, lower, face, face_box)


def clothes_similarity(
    appearance: Appearance,
    target: tuple[np.ndarray, np.ndarray],
    params: ClothesParams,
    relit: bool = False,
) -> float | None:
    """Algorithm 2's clothes similarity S of an appearance against her ``(upper, lower)``
    histograms: the smaller of the two parts' (both must match; a part not seen does not
    count); None if neither was seen. ``relit``: each part's
    :func:`~pfctl.core.perception.clothes.relit_intersection` (the same clothes under other
    light), for evidence that clothes are not hers."""
    s = [
        relit_intersection(h, t, params) if relit else histogram_intersection(h, t)
        for h, t in ((appearance.upper, target[0]), (appearance.lower, target[1]))
        if h is not None
    ]
    return min(s) if s else None


# -- the target's profile ------------------------------------------------------------------------


@dataclass(frozen=True)
class TargetProfile:
    """The target's appearance: normalised upper/lower clothing histograms in ``color_space``
    with ``bins``, and ``faces`` ``(k, 128)`` embeddings (k may be 0)."""

    upper: np.ndarray
    lower: np.ndarray
    faces: np.ndarray
    color_space: ColorSpace = "hsv"
    bins: tuple[int, int, int] = (16, 4, 4)
    frames: int = 0
    """How many frames the profile was learned from."""

    @property
    def clothes(self) -> ClothesParams:
        return ClothesParams(self.color_space, self.bins)

    def face_distance(self, embedding: np.ndarray) -> float | None:
        """Distance of a face to the target's: the median over the profile's embeddings (robust
        to a few odd samples in either direction); None if the profile has no face."""
        if len(self.faces) == 0:
            return None
        return float(np.median(face_distance(self.faces, embedding)))

    def similarity(self, appearance: Appearance, relit: bool = False) -> float | None:
        """Clothes similarity S of an appearance: the smaller of the upper and lower body's
        (both must match; a part not seen does not count); None if neither was seen.
        ``relit``: each part's :func:`~pfctl.core.perception.clothes.relit_intersection` (the
        same clothes under other light)."""
        return clothes_similarity(appearance, (self.upper, self.lower), self.clothes, relit)

    # .npz bytes ----------------------------------------------------------------------------------

    def to_bytes(self) -> bytes:
        """The profile as ``.npz`` bytes (version, histograms, faces, colour space, bins)."""
        buf = io.BytesIO()
        np.savez(
            buf,
            version=np.array(PROFILE_VERSION),
            upper=np.asarray(self.upper, dtype=np.float64),
            lower=np.asarray(self.lower, dtype=np.float64),
            faces=np.asarray(self.faces, dtype=np.float64).reshape(-1, EMBEDDING_SIZE),
            color_space=np.array(self.color_space),
            bins=np.asarray(self.bins, dtype=np.int64),
            frames=np.array(self.frames),
        )
        return buf.getvalue()

    @classmethod
    def from_bytes(cls, data: bytes) -> TargetProfile:
        """The profile in :meth:`to_bytes`'s bytes, checked; ValueError (one line: what is wrong
        and which field) if they are not a usable profile: not an ``.npz`` at all ("not a target
        profile"), a damaged archive ("damaged target profile"), or a field of the wrong kind."""
        if not data.startswith(_ZIP_MAGIC):
            raise ValueError(
                "not a target profile: not an .npz archive (pfctl learn-target writes one)"
            )
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as npz:
                fields = {k: npz[k] for k in npz.files}
        except _DAMAGED as err:
            if "pickle" in str(err):
                raise ValueError(
                    "not a target profile: an array holds pickled Python objects"
                ) from None
            raise ValueError(f"damaged target profile (.npz): {_damage(err)}") from None
        missing = {"version", "upper", "lower", "faces", "color_space", "bins"} - set(fields)
        if missing:
            raise ValueError(f"not a target profile: missing {', '.join(sorted(missing))}")
        version = _integers(fields, "version")
        if version != (PROFILE_VERSION,):
            shown = version[0] if len(version) == 1 else list(version)
            raise ValueError(f"version: expected {PROFILE_VERSION}, got {shown} (learn it again)")
        space = str(fields["color_space"])
        if space not in ("hsv", "rgb", "lab"):
            raise ValueError(f"color_space: expected hsv, rgb or lab, got {space!r}")
        bins = _integers(fields, "bins")
        if len(bins) != 3 or min(bins) < 1:
            raise ValueError(f"bins: expected three positive counts, got {bins}")
        size = int(np.prod(bins))
        upper, lower = (_numbers(fields, k).ravel() for k in ("upper", "lower"))
        for key, h in (("upper", upper), ("lower", lower)):
            if h.size != size or not np.all(np.isfinite(h)) or np.any(h < 0):
                raise ValueError(f"{key}: expected {size} finite non-negative histogram bins")
        faces = _numbers(fields, "faces")
        if faces.ndim != 2 or faces.shape[1] != EMBEDDING_SIZE or not np.all(np.isfinite(faces)):
            raise ValueError(f"faces: expected a (k, {EMBEDDING_SIZE}) array")
        frames = _integers(fields, "frames") if "frames" in fields else (0,)
        if len(frames) != 1:
            raise ValueError(f"frames: expected one count, got {len(frames)} values")
        return cls(
            upper=upper,
            lower=lower,
            faces=faces,
            color_space=space,  # type: ignore[arg-type]
            bins=bins,  # type: ignore[arg-type]
            frames=frames[0],
        )

    def check_params(self, params: IdentityParams, source: str = "profile") -> None:
        """ValueError (one line, starting with ``source``) unless the profile's histograms are in
        the colour space and bins of ``params`` (the mission's)."""
        want = params.clothes
        if (self.color_space, tuple(self.bins)) != (want.color_space, tuple(want.bins)):
            raise ValueError(
                f"{source}: histograms are {self.color_space} {list(self.bins)}, the mission's "
                f"perception.identity wants {want.color_space} {list(want.bins)} (learn it again)"
            )


#: An ``.npz`` is a zip archive; its bytes start with a zip local-file header.
_ZIP_MAGIC = b"PK\x03\x04"
#: What reading the arrays of a damaged archive raises (zip structure, CRC, deflate, .npy
#: headers, object arrays that would need pickle).
_DAMAGED = (
    OSError,
    ValueError,
    EOFError,
    TypeError,
    KeyError,
    NotImplementedError,
    zipfile.BadZipFile,
    zlib.error,
)


def _damage(err: Exception) -> str:
    if isinstance(err, zipfile.BadZipFile) and "not a zip file" in str(err):
        return "truncated or corrupt archive"
    return " ".join(str(err).split()) or type(err).__name__


def _integers(fields: dict[str, np.ndarray], key: str) -> tuple[int, ...]:
    values = np.asarray(fields[key])
    if values.dtype.kind not in "iu":
        raise ValueError(f"{key}: expected integers, got {values.dtype} data")
    return tuple(int(v) for v in values.ravel())


def _numbers(fields: dict[str, np.ndarray], key: str) -> np.ndarray:
    values = np.asarray(fields[key])
    if values.dtype.kind not in "iuf":
        raise ValueError(f"{key}: expected numbers, got {values.dtype} data")
    return values.astype(np.float64)


def learn_profile(
    appearances: Sequence[Appearance],
    params: IdentityParams,
    max_faces: int = MAX_PROFILE_FACES,
) -> TargetProfile:
    """The profile of a person from appearances of them (one per frame): the mean of the
    normalised histograms (renormalised) and up to ``max_faces`` face embeddings spread evenly
    over the samples. ValueError if no appearance has both clothing parts."""
    uppers = [a.upper for a in appearances if a.upper is not None]
    lowers = [a.lower for a in appearances if a.lower is not None]
    if not uppers or not lowers:
        raise ValueError("no appearance shows both the upper and the lower body")

    def mean(hs: list[np.ndarray]) -> np.ndarray:
        m = np.mean(hs, axis=0)
        return m / m.sum()

    faces = [a.face for a in appearances if a.face is not None]
    if len(faces) > max_faces:
        keep = np.linspace(0, len(faces) - 1, max_faces).round().astype(int)
        faces = [faces[i] for i in keep]
    return TargetProfile(
        upper=mean(uppers),
        lower=mean(lowers),
        faces=np.array(faces, dtype=np.float64).reshape(-1, EMBEDDING_SIZE),
        color_space=params.clothes.color_space,
        bins=params.clothes.bins,
        frames=len(appearances),
    )


__all__ = [
    "MAX_PROFILE_FACES",
    "MIN_HEAD_PX",
    "PROFILE_VERSION",
    "Appearance",
    "TargetProfile",
    "clothes_similarity",
    "describe",
    "face_region",
    "head_region",
    "learn_profile",
]
