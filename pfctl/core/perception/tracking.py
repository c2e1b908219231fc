"""Multi-person tracking (Kim et al., §II-E): one Kalman filter per person, Hungarian association.

The paper tracks every person near the robot "with a Kalman filter using a constant velocity
model" and associates new detections to tracks "by minimising the total distance" (the Hungarian
algorithm). This module is that tracker, with a track life cycle and the fusion of two sensors:

**Filter** (filterpy, named as in the textbook). State ``x = (x, y, ẋ, ẏ)`` in the map frame;
``F`` is constant velocity over the tick's ``dt``; ``Q`` is the continuous white-noise
acceleration model (``filterpy.common.Q_continuous_white_noise``, ``q·[[dt³/3, dt²/2], [dt²/2,
dt]]`` per axis) with ``q = process_noise²``, so the velocity drifts by ``process_noise`` m/s per
√s whatever the rate: the 40 Hz laser, the 10 Hz camera and irregular stamps all mean the same
motion model. (The discrete, piecewise-constant form ``Q_discrete_white_noise`` grows the velocity
variance by ``σ²·dt`` per second, 40 times less at 40 Hz than at 1 Hz: at the mission's 0.5 and
40 Hz a person who stops or turns within half a second left the gate and got a new id.) ``H``
picks the position; ``R = σ² I`` per sensor (``laser_noise`` for leg pairs, ``camera_noise`` for
RGB-D people), so a camera detection moves an estimate less than a laser one.

**Tick.** :meth:`MultiPersonTracker.update` first predicts every track to the detections' stamp
(:meth:`~MultiPersonTracker.predict`; irregular ``dt`` from the stamps, ``dt = 0`` allowed, a
stamp older than the tracker's clock is applied at the clock: no retrodiction). It then builds the
cost matrix of Euclidean distances between predicted positions and detections, forbids every pair
whose squared Mahalanobis distance ``νᵀ S⁻¹ ν`` with ``S = H P Hᵀ + R`` exceeds ``gate`` (9.21 is
χ² with 2 dof at 99 %), and solves the assignment with ``scipy.optimize.linear_sum_assignment``
(the total distance is minimised among the assignments with the most gated pairs) — first for
the confirmed and coasting tracks, then for the tentative ones with the detections left (the
matching cascade of SORT-style trackers: a young track never takes a known person's detection).
Associated tracks are corrected; the other detections start tentative tracks, except weak
ones (``Detection.spawn`` False), which are dropped: dual thresholds, a confident detection
starts a track and a weaker one only keeps a track going (Leigh et al. 2015 likewise associate
leg clusters of any confidence with the existing tracks but start tracks only from some).

**Life cycle** (ids are consecutive integers from 1, never reused):

* TENTATIVE → CONFIRMED once it has ``confirm_hits`` detections (the one that created it counts)
  spread over at least ``confirm_s`` seconds, so a 40 Hz laser, a 7.5 Hz one and a replay that
  repeats each scan confirm a person after the same time, not after the same number of scans
  (counted in updates only, 3 hits were 75 ms at 40 Hz: clutter and a track started between two
  people confirmed within one tick); a tentative track unseen for ``tentative_timeout_s`` is
  deleted, so a lone spurious detection never confirms (dense random clutter can chain up inside
  the growing gates: see the benchmark).
* A confirmed track that a sensor's update does not associate becomes COASTING (prediction only,
  its covariance grows) when the track is inside that sensor's field of view (a miss), or when that
  sensor was the last to see it (it left the view and no other sensor has it). A track outside the
  narrow camera view but seen by the laser a moment ago therefore stays CONFIRMED.
* A COASTING track is deleted once unseen for ``max_coast_s`` while its predicted position is
  inside the field of view of the sensor being processed (it should have been seen), or once
  unseen for ``max_coast_unseen_s`` anywhere. A detection inside its gate re-associates it: same
  id, CONFIRMED again — unless the detection is ``new_id_beyond`` or more from where the motion
  model put the track. Then the track goes on under a new id: only a track that coasted a while
  has a gate that wide (it grows with the cube of the time unseen, to metres after 2 s), and
  someone found that far off its course may be another person. Who it is is then for
  identification to say, not for the tracker.

**Fields of view.** :class:`FieldOfView` is a floor wedge (origin pose, half-angle, range
interval); :meth:`FieldOfView.from_scan` also keeps the scan's ranges so that a position behind
the first return along its bearing (a wall, another person) counts as not visible — a person who
walks behind a wall coasts for ``max_coast_unseen_s`` instead of being dropped after
``max_coast_s``. :meth:`FieldOfView.from_frame` is the camera's wedge (horizontal FOV, depth range).
The human belief grid (:mod:`pfctl.core.perception.belief`) uses the same wedge.

Speed: every person has a filterpy ``KalmanFilter`` (x, P, F, Q, H, R), but their predict and
update maths runs for all tracks at once in numpy (:func:`batch_predict`, :func:`batch_update`,
tested equal to filterpy's own ``predict`` / ``update``); gating is batched too.
``benchmarks/bench_tracking_belief.py`` measures a tick with 10 people.
"""

from __future__ import annotations

import enum
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from filterpy.common import Q_continuous_white_noise
from filterpy.kalman import KalmanFilter
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from pfctl.core.params import param
from pfctl.core.robot import LaserScan, Pose2D, RgbdFrame, wrap_angle

LASER = "laser"
CAMERA = "camera"
SENSORS = (LASER, CAMERA)

#: Rate of the leaky confidence score: a hit moves it this fraction toward the detection's
#: confidence, a miss inside the sensor's view this fraction toward 0.
CONFIDENCE_RATE = 0.25

_NOT_GATED = 1e9  # cost of a forbidden pair; larger than any sum of real distances

__all__ = [
    "CAMERA",
    "CONFIDENCE_RATE",
    "LASER",
    "SENSORS",
    "Detection",
    "FieldOfView",
    "MultiPersonTracker",
    "Track",
    "TrackStatus",
    "TrackerParams",
    "batch_predict",
    "batch_update",
]


@dataclass(frozen=True)
class Detection:
    """One person detection in the map frame (m) with the detector's confidence in [0, 1]."""

    x: float
    y: float
    confidence: float = 1.0
    spawn: bool = True
    """Whether the detection may start a track; False: a weak detection, which may only update
    a track whose gate it falls in (dual thresholds)."""


@dataclass(frozen=True)
class FieldOfView:
    """A sensor's view on the floor: the wedge ``|bearing − origin.theta| ≤ half_angle`` between
    ``range_min`` and ``range_max`` from ``origin`` (map frame).

    ``half_angle ≥ π`` is all around. If ``beams`` is given (``(angle_min, angle_increment,
    ranges)`` of a laser scan, angles relative to ``origin.theta``), a point farther than
    ``occlusion_margin`` behind the first return of the beam along its bearing is hidden.
    """

    origin: Pose2D
    half_angle: float
    range_min: float = 0.0
    range_max: float = math.inf
    beams: tuple[float, float, NDArray[np.float64]] | None = field(
        default=None, compare=False, repr=False
    )
    occlusion_margin: float = 0.3

    @classmethod
    def from_scan(cls, scan: LaserScan, *, occlusion: bool = True) -> FieldOfView:
        """The laser's view: the scan's angular span, its range interval and (``occlusion``) the
        returns as occluders."""
        angle_max = scan.angle_min + scan.angle_increment * (len(scan.ranges) - 1)
        centre = 0.5 * (scan.angle_min + angle_max)
        origin = Pose2D(scan.pose.x, scan.pose.y, wrap_angle(scan.pose.theta + centre))
        beams = None
        if occlusion and len(scan.ranges) > 0:
            ranges = np.asarray(scan.ranges, dtype=float)
            beams = (scan.angle_min - centre, scan.angle_increment, ranges)
        return cls(
            origin, 0.5 * abs(angle_max - scan.angle_min), scan.range_min, scan.range_max, beams
        )

    @classmethod
    def from_frame(cls, frame: RgbdFrame, range_max: float, range_min: float = 0.0) -> FieldOfView:
        """The camera's view projected to the floor: apex at the optical centre, heading along
        the optical axis (3rd column of ``camera_rotation``) projected to the floor, half-angle
        half the horizontal FOV, depth-limited to ``[range_min, range_max]``."""
        rotation = np.asarray(frame.camera_rotation, dtype=float)
        forward = rotation[:, 2]
        if math.hypot(forward[0], forward[1]) > 1e-6:
            yaw = math.atan2(forward[1], forward[0])
        else:  # looking straight down: the image's "up" (−y axis) is the floor heading
            yaw = math.atan2(-rotation[1, 1], -rotation[0, 1])
        x, y, _ = frame.camera_position
        return cls(
            Pose2D(float(x), float(y), yaw), 0.5 * frame.info.horizontal_fov, range_min, range_max
        )

    def contains_many(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """For points ``(n, 2)``: True where the point is in view."""
        pts = np.asarray(xy, dtype=float).reshape(-1, 2)
        dx, dy = pts[:, 0] - self.origin.x, pts[:, 1] - self.origin.y
        dist = np.hypot(dx, dy)
        bearing = np.arctan2(dy, dx) - self.origin.theta
        bearing = (bearing + np.pi) % (2.0 * np.pi) - np.pi
        ok = (dist >= self.range_min) & (dist <= self.range_max)
        if self.half_angle < math.pi:
            ok &= np.abs(bearing) <= self.half_angle
        if self.beams is not None:
            angle_min, increment, ranges = self.beams
            index = np.rint((bearing - angle_min) / increment).astype(np.intp)
            inside = (index >= 0) & (index < len(ranges))
            first = np.full(len(pts), np.inf)
            first[inside] = ranges[index[inside]]
            first[~np.isfinite(first)] = np.inf
            ok &= dist <= first + self.occlusion_margin
        return ok

    def contains(self, xy: ArrayLike) -> bool:
        """True if the point ``(x, y)`` is in view."""
        return bool(self.contains_many(xy)[0])


@dataclass(frozen=True)
class TrackerParams:
    """Noise, gate and life cycle of :class:`MultiPersonTracker` (mission ``tracking``)."""

    process_noise: float = param(
        0.5,
        "Continuous white-noise acceleration of the constant-velocity model: √(spectral density),"
        " i.e. the std of the velocity change over one second, whatever the sensor rate.",
        unit="m/s^1.5",
        gt=0,
    )
    laser_noise: float = param(0.05, "Std of a laser (leg pair) position.", unit="m", gt=0)
    camera_noise: float = param(0.15, "Std of a camera position.", unit="m", gt=0)
    gate: float = param(
        9.21,
        "Squared Mahalanobis distance within which a detection may join a track (χ², 2 dof, 99 %).",
        gt=0,
    )
    confirm_hits: int = param(
        3, "A tentative track is confirmed after this many associated detections.", ge=1
    )
    confirm_s: float = param(
        0.2,
        "A tentative track is confirmed only once its detections span at least this long since"
        " the first one (3 hits at 10 Hz), so a person is confirmed after the same time at any"
        " scan rate.",
        unit="s",
        ge=0,
    )
    tentative_timeout_s: float = param(
        0.5, "A tentative track unseen for this long is deleted.", unit="s", gt=0
    )
    max_coast_s: float = param(
        1.5,
        "A confirmed track unseen for this long while inside a sensor's field of view is deleted.",
        unit="s",
        gt=0,
    )
    max_coast_unseen_s: float = param(
        5.0,
        "A confirmed track outside every sensor's field of view coasts this long before deletion.",
        unit="s",
        gt=0,
    )
    new_id_beyond: float = param(
        1.0,
        "A detection that joins a track this far or farther from where the track's motion put"
        " it (only a track that coasted a while has so wide a gate) goes on under a new id:"
        " where it is no longer says who it is, so identification decides afresh.",
        unit="m",
        gt=0,
    )
    initial_speed_std: float = 1.0
    """Std of each velocity component of a new track, m/s (people walk at up to ~1.5 m/s)."""
    spawn_sensors: tuple[str, ...] = SENSORS
    """Sensors whose unassociated detections start tentative tracks."""

    def __post_init__(self) -> None:
        for name in (
            "process_noise",
            "laser_noise",
            "camera_noise",
            "gate",
            "tentative_timeout_s",
            "max_coast_s",
            "max_coast_unseen_s",
            "new_id_beyond",
            "initial_speed_std",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"TrackerParams.{name} must be > 0, got {value}")
        if not (math.isfinite(self.confirm_s) and self.confirm_s >= 0):
            raise ValueError(f"TrackerParams.confirm_s must be ≥ 0, got {self.confirm_s}")
        if self.confirm_hits < 1:
            raise ValueError(f"TrackerParams.confirm_hits must be ≥ 1, got {self.confirm_hits}")
        unknown = set(self.spawn_sensors) - set(SENSORS)
        if unknown:
            raise ValueError(f"TrackerParams.spawn_sensors: unknown sensor(s) {sorted(unknown)}")

    def measurement_std(self, sensor: str) -> float:
        """σ of a position measured by ``sensor`` ("laser" or "camera")."""
        if sensor == LASER:
            return self.laser_noise
        if sensor == CAMERA:
            return self.camera_noise
        raise ValueError(f"unknown sensor {sensor!r}, expected one of {SENSORS}")


class TrackStatus(enum.Enum):
    """Life-cycle state of a track (see the module docstring)."""

    TENTATIVE = "tentative"
    CONFIRMED = "confirmed"
    COASTING = "coasting"


@dataclass(frozen=True)
class Track:
    """A snapshot of one track: state estimate (map frame), position covariance, life cycle."""

    id: int
    status: TrackStatus
    x: float
    y: float
    vx: float
    vy: float
    covariance: NDArray[np.float64] = field(compare=False, repr=False)
    """2x2 covariance of the position, m²."""
    confidence: float
    """Leaky hit/miss score in [0, 1] (:data:`CONFIDENCE_RATE`)."""
    last_seen: float
    """Stamp of the last associated detection, s."""
    sensors_seen: frozenset[str]
    """Sensors that have associated a detection with this track."""
    hits: int

    @property
    def position(self) -> tuple[float, float]:
        return (self.x, self.y)

    @property
    def speed(self) -> float:
        return math.hypot(self.vx, self.vy)


@dataclass
class _Entry:
    """The tracker's mutable record of one track."""

    id: int
    kf: KalmanFilter
    status: TrackStatus
    hits: int
    last_seen: float
    confidence: float
    last_seen_by: dict[str, float]
    first_seen: float

    def snapshot(self) -> Track:
        x = self.kf.x
        return Track(
            id=self.id,
            status=self.status,
            x=float(x[0]),
            y=float(x[1]),
            vx=float(x[2]),
            vy=float(x[3]),
            covariance=self.kf.P[:2, :2].copy(),
            confidence=self.confidence,
            last_seen=self.last_seen,
            sensors_seen=frozenset(self.last_seen_by),
            hits=self.hits,
        )


_H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
_I4 = np.eye(4)


def batch_predict(
    filters: Sequence[KalmanFilter], F: NDArray[np.float64], Q: NDArray[np.float64]
) -> None:
    """``KalmanFilter.predict(F=F, Q=Q)`` of every filter at once (x ← F x, P ← F P Fᵀ + Q).

    The same maths as filterpy's, batched with numpy (one call for all tracks instead of one
    per filter: less Python overhead per tick).
    Sets ``x``, ``P``, ``F``, ``Q`` and the ``x_prior`` / ``P_prior`` copies, as filterpy does.
    """
    if not filters:
        return
    X = np.array([kf.x for kf in filters]) @ F.T
    P = F @ np.array([kf.P for kf in filters]) @ F.T + Q
    for kf, x, cov in zip(filters, X, P, strict=True):
        kf.x, kf.P, kf.F, kf.Q = x, cov, F, Q
        kf.x_prior, kf.P_prior = x.copy(), cov.copy()


def batch_update(
    filters: Sequence[KalmanFilter], Z: NDArray[np.float64], R: NDArray[np.float64]
) -> None:
    """``KalmanFilter.update(z, R=R)`` of filter ``k`` with measurement ``Z[k]``, all at once.

    filterpy's update with H = [I 0] (position measured): ``y = z − H x``, ``S = H P Hᵀ + R``,
    ``K = P Hᵀ S⁻¹``, ``x ← x + K y``, and the Joseph form ``P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ``.
    Sets ``x``, ``P``, ``y``, ``S``, ``SI``, ``K``, ``z``, the ``x_post`` / ``P_post`` copies and
    clears the cached likelihoods, as filterpy does (``R`` is per call, ``kf.R`` is left alone).
    Batched for speed, as :func:`batch_predict`.
    """
    if not filters:
        return
    X = np.array([kf.x for kf in filters])
    P = np.array([kf.P for kf in filters])
    y = Z - X[:, :2]
    S = P[:, :2, :2] + R
    SI = np.linalg.inv(S)
    K = P[:, :, :2] @ SI  # P Hᵀ S⁻¹, (n, 4, 2)
    X = X + np.einsum("nij,nj->ni", K, y)
    IKH = _I4 - K @ _H
    P = IKH @ P @ IKH.transpose(0, 2, 1) + K @ R @ K.transpose(0, 2, 1)
    for k, kf in enumerate(filters):
        kf.x, kf.P, kf.y, kf.S, kf.SI, kf.K = X[k], P[k], y[k], S[k], SI[k], K[k]
        kf.z = Z[k].copy()
        kf.x_post, kf.P_post = X[k].copy(), P[k].copy()
        kf._log_likelihood = kf._likelihood = kf._mahalanobis = None


class MultiPersonTracker:
    """Tracks people with one constant-velocity Kalman filter each and Hungarian association
    minimising the total distance (Kim et al., §II-E); laser and camera detections fuse into the
    same tracks. Deterministic: same calls, same tracks and ids.

    Typical use, once per sensor message::

        fov = FieldOfView.from_scan(scan)
        ids = tracker.update("laser", detections, fov, scan.stamp)
        people = tracker.tracks(confirmed_only=True)
    """

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params or TrackerParams()
        self._entries: list[_Entry] = []
        self._ids = itertools.count(1)
        self._time: float | None = None
        self._motion_cache: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None

    @property
    def time(self) -> float | None:
        """The tracker's clock: the stamp every track is predicted to (None before any call)."""
        return self._time

    # ------------------------------------------------------------------------------- filter

    def _motion(self, dt: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """F and Q (continuous white-noise acceleration) of the constant-velocity model."""
        cached = self._motion_cache
        if cached is not None and cached[0] == dt:
            return cached[1], cached[2]
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        Q = Q_continuous_white_noise(
            dim=2,
            dt=dt,
            spectral_density=self.params.process_noise**2,
            block_size=2,
            order_by_dim=False,
        )
        self._motion_cache = (dt, F, Q)
        return F, Q

    def _new_filter(self, z: tuple[float, float], sigma: float) -> KalmanFilter:
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.x = np.array([z[0], z[1], 0.0, 0.0])
        kf.H = _H.copy()
        kf.R = np.eye(2) * sigma**2
        speed_var = self.params.initial_speed_std**2
        kf.P = np.diag([sigma**2, sigma**2, speed_var, speed_var])
        return kf

    # ---------------------------------------------------------------------------------- tick

    def predict(self, t: float) -> None:
        """Predict every track to time ``t`` (s) and drop tracks unseen for too long.

        ``t`` at or before the tracker's clock predicts nothing (``dt = 0``)."""
        if self._time is None:
            self._time = float(t)
            return
        dt = float(t) - self._time
        if dt > 0:
            F, Q = self._motion(dt)
            filters = [e.kf for e in self._entries]
            batch_predict(filters, F, Q)
            self._time = float(t)
        self._drop_stale()

    def _drop_stale(self) -> None:
        assert self._time is not None
        p, now = self.params, self._time
        self._entries = [
            e
            for e in self._entries
            if now - e.last_seen
            <= (
                p.tentative_timeout_s if e.status is TrackStatus.TENTATIVE else p.max_coast_unseen_s
            )
        ]

    def update(
        self, sensor: str, detections: Sequence[Detection], fov: FieldOfView, t: float
    ) -> list[int | None]:
        """Fuse one sensor message: predict to ``t``, associate, correct, spawn, coast, delete.

        Returns, per detection, the id of the track it updated or started, or None (not
        associated, and ``sensor`` does not start tracks).
        """
        p = self.params
        sigma = p.measurement_std(sensor)
        R = np.eye(2) * sigma**2
        self.predict(t)
        assert self._time is not None
        now = self._time
        z = np.array([[d.x, d.y] for d in detections], dtype=float).reshape(-1, 2)
        pairs = self._associate(z, R)
        out: list[int | None] = [None] * len(detections)
        associated = set()
        # How far each detection is from where the motion model put its track, before the update.
        jump = np.zeros(len(pairs))
        if pairs:
            rows, cols = [i for i, _ in pairs], [j for _, j in pairs]
            predicted = np.array([self._entries[i].kf.x[:2] for i in rows])
            jump = np.hypot(*(z[cols] - predicted).T)
            batch_update([self._entries[i].kf for i in rows], z[cols], R)
        for (i, j), moved in zip(pairs, jump.tolist(), strict=True):
            entry = self._entries[i]
            if moved >= p.new_id_beyond and entry.status is not TrackStatus.TENTATIVE:
                entry.id = next(self._ids)  # far off its course: maybe someone else
            entry.hits += 1
            entry.last_seen = now
            entry.last_seen_by[sensor] = now
            entry.confidence += CONFIDENCE_RATE * (detections[j].confidence - entry.confidence)
            if entry.status is TrackStatus.COASTING or self._confirms(entry, now):
                entry.status = TrackStatus.CONFIRMED
            associated.add(i)
            out[j] = entry.id

        # Unassociated tracks: a miss inside the view, or lost by the sensor that had it last.
        keep: list[_Entry] = []
        missed = [i for i in range(len(self._entries)) if i not in associated]
        in_view = (
            fov.contains_many(np.array([self._entries[i].kf.x[:2] for i in missed]))
            if missed
            else np.zeros(0, dtype=bool)
        )
        seen_in_view = dict(zip(missed, in_view.tolist(), strict=True))
        for i, entry in enumerate(self._entries):
            if i in seen_in_view and entry.status is not TrackStatus.TENTATIVE:
                visible = seen_in_view[i]
                if visible:
                    entry.confidence *= 1.0 - CONFIDENCE_RATE
                lost_here = entry.last_seen_by.get(sensor, -math.inf) >= entry.last_seen
                if visible or lost_here:
                    entry.status = TrackStatus.COASTING
                if visible and now - entry.last_seen > p.max_coast_s:
                    continue  # the sensor should have seen it for max_coast_s: gone
            keep.append(entry)
        self._entries = keep

        if sensor in p.spawn_sensors:
            for j, d in enumerate(detections):
                if out[j] is None and d.spawn:
                    entry = _Entry(
                        id=next(self._ids),
                        kf=self._new_filter((d.x, d.y), sigma),
                        status=TrackStatus.CONFIRMED
                        if p.confirm_hits <= 1 and p.confirm_s <= 0
                        else TrackStatus.TENTATIVE,
                        hits=1,
                        last_seen=now,
                        confidence=CONFIDENCE_RATE * d.confidence,
                        last_seen_by={sensor: now},
                        first_seen=now,
                    )
                    self._entries.append(entry)
                    out[j] = entry.id
        return out

    def _confirms(self, entry: _Entry, now: float) -> bool:
        """A tentative track with ``confirm_hits`` detections over at least ``confirm_s``."""
        p = self.params
        # 1e-9: stamps summed from a scan period (k · 0.025) must not miss the bound by rounding.
        return entry.hits >= p.confirm_hits and now - entry.first_seen >= p.confirm_s - 1e-9

    def _associate(self, z: NDArray[np.float64], R: NDArray[np.float64]) -> list[tuple[int, int]]:
        """(track index, detection index) pairs: Hungarian assignment minimising the total
        Euclidean distance (§II-E) among pairs inside the Mahalanobis gate ``νᵀ S⁻¹ ν ≤ gate``
        (``S = H P Hᵀ + R``); confirmed and coasting tracks first, tentative ones get the rest."""
        if not self._entries or len(z) == 0:
            return []
        pos = np.array([e.kf.x[:2] for e in self._entries])
        S = np.array([e.kf.P[:2, :2] for e in self._entries]) + R
        S_inv = np.linalg.inv(S)
        nu = z[None, :, :] - pos[:, None, :]  # (tracks, detections, 2)
        d2 = np.einsum("tdi,tij,tdj->td", nu, S_inv, nu)
        gated = d2 <= self.params.gate
        if not gated.any():
            return []
        dist = np.hypot(nu[..., 0], nu[..., 1])
        tentative = np.array([e.status is TrackStatus.TENTATIVE for e in self._entries])
        free = np.ones(len(z), dtype=bool)
        pairs: list[tuple[int, int]] = []
        for stage in (~tentative, tentative):
            rows, cols = np.flatnonzero(stage), np.flatnonzero(free)
            if len(rows) == 0 or len(cols) == 0:
                continue
            ok = gated[np.ix_(rows, cols)]
            if not ok.any():
                continue
            cost = np.where(ok, dist[np.ix_(rows, cols)], _NOT_GATED)
            for r, c in zip(*linear_sum_assignment(cost), strict=True):
                if ok[r, c]:
                    pairs.append((int(rows[r]), int(cols[c])))
                    free[cols[c]] = False
        return pairs

    # ------------------------------------------------------------------------------- queries

    def tracks(self, *, confirmed_only: bool = False) -> list[Track]:
        """Snapshots of the tracks in id order; ``confirmed_only`` leaves out TENTATIVE ones
        (COASTING tracks are confirmed people that are not seen right now, so they stay)."""
        return [
            e.snapshot()
            for e in self._entries
            if not (confirmed_only and e.status is TrackStatus.TENTATIVE)
        ]

    def track(self, track_id: int) -> Track | None:
        """The track with this id, or None if it never existed or was deleted."""
        for e in self._entries:
            if e.id == track_id:
                return e.snapshot()
        return None

    def __len__(self) -> int:
        return len(self._entries)
