"""The robot's sense of people (§II-E): laser legs and camera people → tracks → who is the target.

One :class:`Perception` holds the parts of the paper's perception and runs them per sensor
message, in the order of their stamps (:func:`in_stamp_order`: every scan of an observation at
its own stamp and laser pose, as leg_tracker and SPENCER track on every scan; the camera's frame
between the scans taken before and after it):

- a **scan** → :class:`~pfctl.core.perception.legs.detector.LegDetector` (segments, Arras et
  al. features, random forest, leg pairs) → person candidates, and a lone leg (one leg segment:
  a person standing side-on shows one) within :data:`SINGLE_LEG_DISTANCE` of a person the
  camera saw in its latest frame (at most :data:`CAMERA_MAX_AGE` old) and whose legs made no
  candidate as a candidate too, at
  the two positions fused (weighted by the tracker's laser and camera noise) — the camera says
  someone stands there, the leg that it is a person's legs the laser sees; lone legs far from
  any camera detection (a table's legs) stay no one →
  :class:`~pfctl.core.perception.tracking.MultiPersonTracker` (``laser`` detections, the scan's
  field of view with its returns as occluders). With the static map's occupied cells given
  (``occupied``), the legs and candidates inside them are dropped first: nobody stands inside a
  wall or a piece of furniture, and what the forest takes for a leg there is the map's own
  clutter (the end faces of door jambs, a wall's corner), which would pull a coasting track onto
  it or start a person who is not there;
- an **RGB-D frame** → a :class:`~pfctl.core.perception.vision.PersonDetector` → 3-D people →
  the same tracker (``camera`` detections, the camera's floor wedge) → Algorithm 2
  (:class:`~pfctl.core.perception.identity.identifier.TargetIdentifier`, one call per frame) for
  every track the camera saw, with "has legs" meaning the laser has associated leg detections
  with that track (with a face worker, its results are folded in there too), after telling it
  where every track is (who is seen beside her, who stands close to whom); and, when a
  :class:`~pfctl.core.perception.belief.HumanBelief` is given, the Eq. 4 update of the camera's
  view.

The target is the track the identifier names (kept while the tracker has it, switched only on
confirmation), as long as the tracker still has it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pfctl.core.episode import TrackRow
from pfctl.core.mapping.grid import GridGeometry
from pfctl.core.perception.belief import HumanBelief
from pfctl.core.perception.identity.identifier import Decision, TargetIdentifier, TrackIdentity
from pfctl.core.perception.legs.detector import (
    SINGLE_LEG_FACTOR,
    ClassifiedSegments,
    LegDetections,
    LegDetector,
)
from pfctl.core.perception.tracking import (
    Detection,
    FieldOfView,
    MultiPersonTracker,
    Track,
    TrackStatus,
)
from pfctl.core.perception.vision import PersonDetection, PersonDetector
from pfctl.core.robot import LaserScan, Observation, RgbdFrame

#: A lone leg this close to a person the camera sees is that person's, metres.
SINGLE_LEG_DISTANCE = 0.4
#: A camera frame's people are used for the lone legs of the scans up to this much later, s
#: (a frame period and a half at the camera's 10 Hz).
CAMERA_MAX_AGE = 0.15


@dataclass(frozen=True)
class CameraSighting:
    """A person the camera saw in one frame, the track it was associated with (None: no
    track) and, with an identifier, that track's identity after this frame."""

    detection: PersonDetection
    track_id: int | None
    identity: TrackIdentity | None


class Perception:
    """Legs + vision → tracking → identification (+ belief), fed one sensor message at a time."""

    def __init__(
        self,
        legs: LegDetector,
        tracker: MultiPersonTracker,
        *,
        detector: PersonDetector | None = None,
        identifier: TargetIdentifier | None = None,
        belief: HumanBelief | None = None,
        camera_range: tuple[float, float] = (0.4, 8.0),
        occupied: tuple[GridGeometry, NDArray[np.bool_]] | None = None,
    ) -> None:
        """``detector`` None: the camera is not used; ``identifier`` None: no target is
        identified; ``camera_range``: the depth interval (m) in which the camera sees people;
        ``occupied``: the static map's geometry and its occupied cells (walls, furniture), where
        no leg is (None: no map, every leg counts)."""
        self.legs = legs
        self.occupied = occupied
        self.tracker = tracker
        self.detector = detector
        self.identifier = identifier
        self.belief = belief
        self.camera_range = camera_range
        self._leg_tracks: set[int] = set()
        self.last_legs: LegDetections | None = None
        self.last_sightings: tuple[CameraSighting, ...] = ()
        self._camera_people: tuple[float, np.ndarray] | None = None
        """The latest frame's stamp and the floor positions ``(n, 2)`` of its people."""
        self.last_visible: NDArray[np.bool_] | None = None
        """The belief grid's cells the last frame saw (Eq. 4's visible mask; None without a
        belief or a frame yet)."""
        self.camera_hfov: float | None = None
        """The camera's horizontal field of view, rad (None before the first frame)."""

    def on_scan(
        self, scan: LaserScan, classified: ClassifiedSegments | None = None
    ) -> LegDetections:
        """Detect legs in ``scan`` and update the tracks with the person candidates.
        ``classified``: the scan's segments as :meth:`LegDetector.classify` gave them with the
        other scans of a tick (None: classified here)."""
        tracked = None
        if self.legs.scene is not None:  # the static-scene filter spares the tracked people
            tracked = np.array([t.position for t in self.tracks()], dtype=float).reshape(-1, 2)
        found = self._off_the_map(self.legs.detect(scan, tracked, classified))
        detections = [Detection(p.x, p.y, p.probability) for p in found.people]
        detections += self._legs_beside_camera_people(found)
        detections += [Detection(p.x, p.y, p.probability, spawn=False) for p in found.weak]
        ids = self.tracker.update("laser", detections, FieldOfView.from_scan(scan), scan.stamp)
        self._leg_tracks.update(i for i in ids if i is not None)
        self._forget_deleted()
        self.last_legs = found
        return found

    def _off_the_map(self, found: LegDetections) -> LegDetections:
        """``found`` without the legs and candidates that lie in an occupied cell of the static
        map (``occupied``; the module docstring)."""
        if self.occupied is None:
            return found
        geometry, occupied = self.occupied

        def free(items: Sequence[Any]) -> tuple[Any, ...]:
            if not items:
                return ()
            rows, cols = geometry.world_to_cell([(i.x, i.y) for i in items])
            inside = geometry.in_bounds(rows, cols)
            hit = np.zeros(len(items), dtype=bool)
            hit[inside] = occupied[rows[inside], cols[inside]]
            return tuple(i for i, h in zip(items, hit, strict=True) if not h)

        return replace(
            found,
            legs=free(found.legs),
            people=free(found.people),
            lone_legs=free(found.lone_legs),
            weak=free(found.weak),
        )

    def on_frame(self, frame: RgbdFrame) -> tuple[CameraSighting, ...]:
        """Detect people in ``frame``, update the tracks, identify them and the belief."""
        if self.detector is None:
            return ()
        people = self.detector.detect(frame)
        self.camera_hfov = frame.info.horizontal_fov
        fov = FieldOfView.from_frame(frame, self.camera_range[1], self.camera_range[0])
        detections = [Detection(d.position[0], d.position[1], d.score) for d in people]
        self._camera_people = (frame.stamp, np.array([[d.x, d.y] for d in detections]))
        ids = self.tracker.update("camera", detections, fov, frame.stamp)
        self._forget_deleted()
        identities: dict[int, TrackIdentity] = {}
        if self.identifier is not None:
            tracks = self.tracker.tracks()
            self.identifier.note_tracks(
                frame.stamp, [(t.id, t.x, t.y, t.status is TrackStatus.CONFIRMED) for t in tracks]
            )
            seen = [
                (track_id, track_id in self._leg_tracks, person)
                for person, track_id in zip(people, ids, strict=True)
                if track_id is not None
            ]
            # everyone the tracker has near the camera, seen by it or not (hidden behind another)
            cx, cy, _ = frame.camera_position
            reach = self.identifier.params.handoff_range
            near = [
                t.id
                for t in tracks
                if t.status is not TrackStatus.TENTATIVE and math.hypot(t.x - cx, t.y - cy) <= reach
            ]
            found = self.identifier.observe_frame(frame.stamp, frame.rgb, seen, near=near)
            identities = {s[0]: identity for s, identity in zip(seen, found, strict=True)}
        sightings = [
            CameraSighting(person, track_id, None if track_id is None else identities.get(track_id))
            for person, track_id in zip(people, ids, strict=True)
        ]
        if self.belief is not None:
            self.last_visible = self.belief.update(
                fov, [d.position[:2] for d in people], frame.stamp
            )
        self.last_sightings = tuple(sightings)
        return self.last_sightings

    def _legs_beside_camera_people(self, found: LegDetections) -> list[Detection]:
        """Person candidates from lone legs beside the people of the latest camera frame (the
        module docstring): each person the camera saw with no leg candidate within
        :data:`SINGLE_LEG_DISTANCE` takes the nearest lone leg within that distance, at the
        inverse-variance mean of the two positions, with the single leg's confidence (P(leg) ×
        ``SINGLE_LEG_FACTOR``)."""
        recent = self._camera_people
        if not found.lone_legs or recent is None or len(recent[1]) == 0:
            return []
        stamp, people = recent
        if not 0.0 <= found.stamp - stamp <= CAMERA_MAX_AGE:
            return []
        if found.people:  # a person whose legs already made a candidate needs none
            cands = np.array([[c.x, c.y] for c in found.people])
            gap = np.hypot(
                people[:, None, 0] - cands[None, :, 0], people[:, None, 1] - cands[None, :, 1]
            )
            people = people[gap.min(axis=1) > SINGLE_LEG_DISTANCE]
            if len(people) == 0:
                return []
        legs = np.array([[leg.x, leg.y] for leg in found.lone_legs])
        d = np.hypot(people[:, None, 0] - legs[None, :, 0], people[:, None, 1] - legs[None, :, 1])
        w_leg = self.tracker.params.laser_noise**-2
        w_cam = self.tracker.params.camera_noise**-2
        out: list[Detection] = []
        taken: set[int] = set()
        for i in np.argsort(d.min(axis=1), kind="stable"):
            near = [j for j in np.argsort(d[i], kind="stable") if j not in taken]
            if not near or d[i, near[0]] > SINGLE_LEG_DISTANCE:
                continue
            j = int(near[0])
            taken.add(j)
            xy = (w_leg * legs[j] + w_cam * people[i]) / (w_leg + w_cam)
            p = found.lone_legs[j].probability * SINGLE_LEG_FACTOR
            out.append(Detection(float(xy[0]), float(xy[1]), p))
        return out

    def on_observation(self, observation: Observation) -> None:
        """Feed what one :class:`~pfctl.core.robot.Observation` brings (its scans and its frame)
        in the order of their stamps (:func:`in_stamp_order`)."""
        for message in in_stamp_order(observation):
            if isinstance(message, LaserScan):
                self.on_scan(message)
            else:
                self.on_frame(message)

    def _forget_deleted(self) -> None:
        alive = {t.id for t in self.tracker.tracks()}
        self._leg_tracks &= alive
        if self.identifier is not None:
            for gone in self.identifier.known_tracks() - alive:
                self.identifier.forget(gone)

    def tracks(self, *, confirmed_only: bool = True) -> list[Track]:
        """The current tracks (by default the confirmed and coasting ones)."""
        return self.tracker.tracks(confirmed_only=confirmed_only)

    def target(self) -> Track | None:
        """The target's track: the one Algorithm 2 names, if the tracker still has it."""
        if self.identifier is None:
            return None
        track_id = self.identifier.target_track()
        return None if track_id is None else self.tracker.track(track_id)

    def candidate(self) -> Track | None:
        """The ambiguous person worth a look at the face (the identifier's
        :meth:`~pfctl.core.perception.identity.identifier.TargetIdentifier.candidate_track`), if
        the tracker still has them."""
        if self.identifier is None:
            return None
        track_id = self.identifier.candidate_track()
        return None if track_id is None else self.tracker.track(track_id)

    def strangers(self, now: float, max_age: float) -> list[Track]:
        """The people no camera frame has shown yet: tracks measured within ``max_age`` s of
        ``now`` that Algorithm 2 holds nothing about (the laser's legs alone)."""
        if self.identifier is None:
            return []
        return [
            t
            for t in self.tracks()
            if now - t.last_seen <= max_age and self.identifier.identity(t.id) is None
        ]

    def not_target(self, exclude: int | None = None) -> list[tuple[float, float]]:
        """Where the people are whose tracks Algorithm 2 has identified as not the target (track
        ``exclude`` left out)."""
        if self.identifier is None:
            return []
        others = {
            tid
            for tid, ident in self.identifier.identities().items()
            if ident.decision is Decision.NOT_TARGET
        }
        return [t.position for t in self.tracks() if t.id in others and t.id != exclude]

    def seen_track_rows(self, stamp: float) -> list[TrackRow]:
        """One :func:`track_rows` row per confirmed track seen now (coasting tracks, which are
        extrapolations, are left out), stamped ``stamp``: what ``pfctl replay`` writes after a
        scan and what the follower logs after each tick with a scan."""
        seen = [t for t in self.tracks() if t.status is TrackStatus.CONFIRMED]
        target = self.target()
        return track_rows(stamp, seen, target and target.id)

    def has_legs(self, track_id: int) -> bool:
        """Whether the laser has associated leg detections with ``track_id``."""
        return track_id in self._leg_tracks

    def close(self) -> None:
        """Release what the perception holds (the identifier's face worker); safe to call twice."""
        if self.identifier is not None:
            self.identifier.close()


def in_stamp_order(observation: Observation) -> list[LaserScan | RgbdFrame]:
    """The observation's scans and frame in the order of their stamps; a scan with the frame's
    stamp comes first, so that its lone legs meet the previous frame's people, as they did when
    one scan came per tick."""
    messages: list[LaserScan | RgbdFrame] = list(observation.scans)
    frame = observation.rgbd
    if frame is not None:
        after = [k for k, scan in enumerate(messages) if scan.stamp > frame.stamp]
        messages.insert(after[0] if after else len(messages), frame)
    return messages


def track_rows(stamp: float, tracks: Sequence[Track], target_id: int | None) -> list[TrackRow]:
    """One ``(t, track_id, x, y, vx, vy, confidence, is_target)`` row per track."""
    return [(stamp, t.id, t.x, t.y, t.vx, t.vy, t.confidence, t.id == target_id) for t in tracks]


__all__ = ["CameraSighting", "Perception", "in_stamp_order", "track_rows"]
