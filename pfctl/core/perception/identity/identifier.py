"""Target identification, Algorithm 2 of the paper (§II-E): legs, then face, then clothes.

The paper decides which tracked person is the target by filtering the candidates: first those
with legs (the laser's leg detector, so a poster or a coat on a chair is not a person), then by
face (an embedding distance below ``face_distance``), then by clothes (the histogram intersection
``S = Σ min(I, T) / Σ T`` of :mod:`pfctl.core.perception.clothes` above ``clothes_similarity``).

Faces are trusted most. A face match confirms a track as the target, a face mismatch rejects it
even if the clothes match (a look-alike in the same shirt). The paper applies the filter to each
frame; here **the evidence is kept per track over time** and weighed as a log-odds belief
(:mod:`~pfctl.core.perception.identity.log_odds`: face, clothes only as far as they separate her
from the people about, a distractor mark, continuity), so one good face match carries the track
through the later frames where the person turns their back, and a mismatching face is remembered
the same way. When a track has seen faces both ways (a bad detection, or a track the tracker
swapped onto someone else), the median of its newest ``face_recent`` face distances decides.

**Who is the target** is a name, not a choice made again each frame (issue 23): the named track
stays the target while the tracker holds it and it is not decided NOT_TARGET nor below TARGET for
``doubt_s`` (a face that does not quite match, clothes that stopped matching: she is lost rather
than followed on doubt) — unless another track shows her face more recently by ``face_recheck_s``
(the named one was swapped), and unless another person comes within ``swap_distance`` of it where
the camera cannot tell the two apart (in her clothes, or her track out of the camera's view: the
tracker may swap people who cross). A new track is named at once on a face match, else only after
``confirm_frames`` identifications in a row at TARGET over ``confirm_s`` at least (time to go and
see the face); while a look-alike is about, clothes are no evidence, so only a face names anyone
and otherwise she is lost. A new track that takes her on where her named track was left (the
camera first saw it there within a second and has not seen the old one since: the tracker lost
her legs for a moment) is her, not a look-alike: the name follows her onto it after
``SPLIT_FRAMES`` identifications at TARGET. So does a track that took her on from her named
track — picked up anew there, swapped with it by a passer-by in other clothes, or one of the two
after such a passer-by crossed her out of the camera's view — while every other person in her
clothes seen so far is accounted for elsewhere: on such a track her clothes count though a
look-alike is about (:meth:`TargetIdentifier._took_her_on`). The one exception is the start of
a run, the **hand-off**: the one person tracked within ``handoff_range`` of the camera in the
first ``handoff_s``, in her clothes, is the person the robot was just shown and is named at once. A
look-alike is about while another track matches her clothes, and for ``look_alike_memory_s``
after a person in her clothes was rejected by face, marked a distractor, or tracked at least
``coexist_distance`` from another person in her clothes at once (one of the two at most is her).
People found not to be her are remembered (:mod:`~pfctl.core.perception.identity.distractors`):
rejected by face, or seen at the same time as her face-confirmed track away from her
(:meth:`TargetIdentifier.note_tracks`); a new track where one of them was lost stays rejected.
Her clothes are learned online, only from frames where a face confirms her and no one else is
within ``update_clearance``. An ambiguous person (her clothes, no face yet) is offered as
:meth:`TargetIdentifier.candidate_track` for the robot to go and see the face.

Faces are searched only when it is worth it: until a track has ``face_settled`` face samples, then
every ``face_recheck_s``; and a track whose last ``face_miss_limit`` searches found no face (the
back of the head, a face turned away) is searched only every ``face_miss_backoff_s`` until one
is found again.

Clothes are measured on every observation until the track's clothes evidence is **settled**:
``clothes_settled`` samples and either a face deciding the track (then clothes no longer enter
Algorithm 2's decision at all) or a similarity (below) at least ``clothes_margin`` away from the
``clothes_similarity`` threshold. A settled track's clothes are measured again only every
``clothes_recheck_s`` (a histogram pair per person and frame adds up in a crowd;
benchmarks/bench_identity.py measures it). The decision is the median S of the newest
``clothes_recent`` samples, so a track the tracker slid onto someone else shows it within a few
samples, and one odd sample (an arm across the shirt) does not; a track whose median comes back
within the margin of the threshold is measured on every frame again, and so is the named track's.
A track whose clothes turn clearly unlike hers has slid onto someone else: the faces of hers it
showed before are forgotten (they are not this person's), and if named it loses the name at
once. "Unlike hers" is always judged on the **relit** similarity (the same clothes under other
light, :func:`~pfctl.core.perception.clothes.relit_intersection`): the clothes count against a
track, unlike hers, only when they are unlike hers under every light; that they are hers is
judged on the plain one.

The face search itself (dlib's HOG detector and ResNet embedding, far more than a tick's budget
per face; benchmarks/bench_identity.py) runs inline by default, or — given a
:class:`~pfctl.core.perception.face_worker.FaceWorker` — in a worker process: the head crop is
submitted and the result folded into the track's evidence when it comes back (a track deleted
meanwhile is skipped). How results are folded in is ``face_timing``:

- ``deterministic`` (the simulator): a search submitted with the frame stamped t is folded in at
  the first observation stamped t + ``face_latency_s`` or later, waiting for the worker then if
  it is not done; at most ``max_in_flight`` searches are out, counted by the identifier itself.
  Which searches are made and when their results count depend on the frames' stamps only, so a
  seeded simulation gives the same episode however fast the machine is;
- ``realtime`` (a real robot): whatever has come back is folded in at each observation, nothing
  waits; a search the worker refuses (it is busy) is tried again on a later frame.

``auto``, which the app resolves for the robot it runs on, counts as ``deterministic`` here
(:attr:`~pfctl.core.perception.identity.params.IdentityParams.timing`).
"""

from __future__ import annotations

import enum
import itertools
import math
import time
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from pfctl.core.perception.clothes import convert
from pfctl.core.perception.faces import Box, Face, FaceEncoder
from pfctl.core.perception.identity.distractors import DistractorMemory
from pfctl.core.perception.identity.log_odds import Cues, log_odds
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import (
    Appearance,
    TargetProfile,
    clothes_similarity,
    describe,
    face_region,
)
from pfctl.core.perception.vision import PersonDetection

if TYPE_CHECKING:
    from pfctl.core.perception.face_worker import FaceResult, FaceWorker

#: Stamps this close count as equal (simulated clocks add up float steps).
STAMP_EPS = 1e-6

#: Clothes measured this long ago or less count as a track's clothes now (two settled tracks
#: are measured every ``clothes_recheck_s``, 0.5 s by default).
FRESH_CLOTHES_S = 1.0

#: How many clothes samples unlike hers, taken while no one else overlapped the person in the
#: image, make them someone other than her for the hand-off (:meth:`TargetIdentifier._may_be_her`).
CLEAR_SAMPLES = 3

#: A track the camera first saw at most this long after it last saw another, where that one was,
#: may be the same person picked up anew by the tracker (:meth:`TargetIdentifier._split`), s.
SPLIT_GAP_S = 1.0
#: ... and is named in her place after this many identifications in a row at TARGET with the
#: other unseen (not on one frame: two people seen in turns are not one picked up anew).
SPLIT_FRAMES = 3
#: After a passer-by in other clothes crossed her named track out of the camera's view (the
#: name went, :meth:`TargetIdentifier._note_crossing`), the one of the two tracks that shows her
#: clothes on this many fresh samples in a row within this long, s, took her on.
CROSSED_S = 5.0
#: A person in her clothes last seen this long ago may have walked this fast since, m/s
#: (:meth:`TargetIdentifier._look_alikes_elsewhere`; the crowd's walkers reach 1.5 m/s).
LOOK_ALIKE_SPEED = 1.5

#: Her named track, back in the camera's view after this long unseen, is judged on the clothes
#: measured since (``_Evidence.back_at``), s: the tracker may have carried it onto someone else
#: meanwhile, and what it showed before is the other person's.
BACK_GAP_S = 0.5

#: Numbers the identifiers, for their job keys.
_IDENTIFIERS = itertools.count()

# -- per-track decisions -------------------------------------------------------------------------


def _overlapped(
    detection: PersonDetection, sightings: Sequence[tuple[int, bool, PersonDetection | None]]
) -> bool:
    """Whether another person's box in the frame overlaps ``detection``'s columns."""
    x0, _, x1, _ = detection.box
    return any(
        other is not None and other is not detection and other.box[0] < x1 and x0 < other.box[2]
        for _, _, other in sightings
    )


class Decision(enum.Enum):
    """What Algorithm 2 concludes about a track."""

    TARGET = "target"
    NOT_TARGET = "not_target"
    UNKNOWN = "unknown"


@dataclass(frozen=True)
class TrackIdentity:
    """The evidence gathered about one track and the decision it supports."""

    track_id: int
    decision: Decision
    confidence: float
    """The probability of the decision from the log-odds (``1 / (1 + e^-|L|)``); 0 for
    UNKNOWN."""
    basis: str
    """The cue that weighs most: ``face``, ``distractor``, ``clothes``, ``continuity``,
    ``no_legs`` or ``nothing``."""
    face_distance: float | None
    """Median face distance to the profile over the track's face samples (None: no face yet)."""
    best_face_distance: float | None
    clothes_similarity: float | None
    """Clothes similarity S: the median of the track's newest ``clothes_recent`` samples (None:
    never measured)."""
    face_samples: int
    clothes_samples: int
    observations: int
    legs_seen: int
    last_seen: float
    face_box: Box | None = None
    """Where the face was found, when a face was folded in at this identity's time (inline: in
    this observation's frame; with a worker: in the frame the search was submitted from)."""
    log_odds: float = 0.0
    """The belief that the track is the target (:mod:`~pfctl.core.perception.identity.log_odds`)."""
    clothes_relit: float | None = None
    """The relit clothes similarity (the same clothes under other light,
    :func:`~pfctl.core.perception.clothes.relit_intersection`), as ``clothes_similarity``: only
    it says that clothes are *not* hers."""


@dataclass
class _Evidence:
    face_distances: list[float] = field(default_factory=list)
    last_face: float = -math.inf
    """Stamp of the frame of the newest face sample."""
    clothes: list[float] = field(default_factory=list)
    clothes_relit: list[float] = field(default_factory=list)
    """The relit similarity of each of ``clothes``' samples."""
    observations: int = 0
    legs_seen: int = 0
    last_seen: float = -math.inf
    last_search: float = -math.inf
    """Stamp of the frame of the newest face search (made or submitted)."""
    face_misses: int = 0
    """Face searches in a row that found no face."""
    last_clothes: float = -math.inf
    """Stamp of the frame of the newest clothes measurement."""
    face_box: Box | None = None
    face_box_at: float = math.nan
    """When ``face_box`` was folded in: identities made then report it."""
    job: tuple[int, int] | None = None
    """The face search of this track out at the worker, if any."""
    xy: tuple[float, float] | None = None
    """Where the camera last saw the track (map frame)."""
    first_xy: tuple[float, float] | None = None
    """Where the camera first saw the track (map frame)."""
    first_detected: float = math.inf
    last_detected: float = -math.inf
    """Stamps of the first and the newest frame the camera saw the track in."""
    upper: np.ndarray | None = None
    lower: np.ndarray | None = None
    """The newest clothing histograms measured."""
    distractor: str | None = None
    """Known not to be her without a face: ``coexisted`` or ``linked`` (distractor memory)."""
    slid: bool = False
    """The track slid off a distractor's mark onto someone in her clothes
    (:meth:`TargetIdentifier._check_slid_off_distractor`): only a face names it, unless it took
    her on from her named track (:meth:`TargetIdentifier._took_her_on`)."""
    streak: int = 0
    """Identifications in a row at TARGET (the confirmation of a switch without a face)."""
    last_match: float = -math.inf
    """Stamp of the frame of the newest face sample that matched hers."""
    streak_since: float = math.inf
    """When the current run of identifications at TARGET began."""
    below_since: float = math.inf
    """When the current run of identifications below TARGET began (a named track in doubt
    for ``doubt_s`` loses the name)."""
    unlike_since: float = math.inf
    """Since when the track's clothes have been clearly unlike hers (inf: they are not)."""
    unlike_until: float = -math.inf
    """The newest stamp at which the track's clothes were clearly unlike hers."""
    clear_clothes: list[float] = field(default_factory=list)
    """Relit clothes samples taken while no other person's box overlapped this one's (a person
    half hidden behind another shows partly the other's clothes)."""
    back_at: int = 0
    """The index of the first clothes sample since the track, named, came back into the
    camera's view after :data:`BACK_GAP_S` or more unseen (0: from the start): its clothes
    evidence is what it showed since."""

    def face(self, recent: int) -> float | None:
        """The median distance of the newest ``recent`` face samples (None: no face yet): a
        track the tracker swapped onto someone else shows it within a few faces."""
        if not self.face_distances:
            return None
        return float(np.median(self.face_distances[-recent:]))

    def clothes_now(self, recent: int) -> float | None:
        """The median clothes similarity of the newest ``recent`` samples, taken since the track
        last came back into view (``back_at``; None: never measured): a track the tracker slid
        onto someone else shows it within a few samples, where the mean over the track's life
        would hide it for long."""
        fresh = self.clothes[max(self.back_at, len(self.clothes) - recent) :]
        return float(np.median(fresh)) if fresh else None

    def relit_now(self, recent: int) -> float | None:
        """:meth:`clothes_now` of the relit similarities."""
        fresh = self.clothes_relit[max(self.back_at, len(self.clothes_relit) - recent) :]
        return float(np.median(fresh)) if fresh else None


@dataclass(frozen=True)
class _Job:
    """A face search out at the worker."""

    job: tuple[int, int]
    track_id: int
    evidence: _Evidence
    stamp: float
    """Stamp of the frame the head was cropped from."""
    due: float
    """Deterministic timing: folded in at the first observation stamped this or later."""


@dataclass
class FaceSearchStats:
    """What the identifier did about faces and clothes (counters since it was made)."""

    inline: int = 0
    """Searches run inline (no worker)."""
    submitted: int = 0
    """Searches submitted to the worker."""
    refused: int = 0
    """Searches the worker refused (busy; tried again on a later frame)."""
    deferred: int = 0
    """Searches due but not submitted because ``max_in_flight`` were out (deterministic)."""
    folded: int = 0
    """Worker results folded into a track's evidence."""
    discarded: int = 0
    """Worker results whose track was deleted meanwhile."""
    backed_off: int = 0
    """Searches skipped because the track's searches kept missing (``face_miss_limit``)."""
    too_small: int = 0
    """Faces found but smaller than ``min_face_px``: not used as evidence."""
    waited_s: float = 0.0
    """Wall time spent waiting for the worker (deterministic timing), seconds."""
    clothes_measured: int = 0
    """Clothing histogram pairs measured (one per seen track and frame when due)."""
    clothes_skipped: int = 0
    """Clothes measurements skipped because the track was settled (``clothes_recheck_s``)."""


class TargetIdentifier:
    """Algorithm 2 over time: feed each track's observations, ask which track is the target.

    ``observe(track_id, t, has_legs, detection, rgb)`` adds one observation of a track (the
    detection associated with it in this frame, or None when the camera did not see it) and
    returns the track's current :class:`TrackIdentity`; :meth:`observe_frame` does the same for
    all the tracks one frame saw (converting the frame's colours once, and giving the worker's
    few slots to the tracks searched longest ago). A track is a candidate only once the leg
    detector has confirmed it (``has_legs``) at least once. Faces are searched as the module
    docstring says (settled tracks every ``face_recheck_s``, missing ones backed off); clothes
    are measured every time.

    ``worker`` (a :class:`~pfctl.core.perception.face_worker.FaceWorker`): faces are searched there,
    with ``params.timing``; without one they are searched inline with ``encoder`` (default: a
    :class:`~pfctl.core.perception.faces.FaceEncoder` of ``params.face``). :meth:`close` closes the
    worker.
    """

    def __init__(
        self,
        profile: TargetProfile,
        params: IdentityParams | None = None,
        encoder: FaceEncoder | None = None,
        *,
        worker: FaceWorker | None = None,
    ) -> None:
        self.params = params or IdentityParams(clothes=profile.clothes)
        profile.check_params(self.params)
        if self.params.face_timing not in ("auto", "deterministic", "realtime"):
            raise ValueError(f"face_timing: unknown {self.params.face_timing!r}")
        self.profile = profile
        use_faces = self.params.faces and len(profile.faces) > 0
        self.worker = worker if use_faces else None
        self.encoder = (
            (encoder or FaceEncoder(self.params.face)) if use_faces and worker is None else None
        )
        self.face_stats = FaceSearchStats()
        self._tracks: dict[int, _Evidence] = {}
        self._latest: dict[int, TrackIdentity] = {}
        self._jobs: dict[tuple[int, int], _Job] = {}
        """Searches out at the worker, in the order submitted."""
        self._arrived: dict[tuple[int, int], FaceResult] = {}
        self._next_job = 0
        self._key = next(_IDENTIFIERS)
        """Job keys are ``(key, n)``: several identifiers may share one worker."""
        self._given_worker = worker
        self.distractors = DistractorMemory(
            link_radius=self.params.coexist_distance,
            clothes_match=self.params.clothes_similarity,
        )
        """The people found not to be her (issue 23, item 4)."""
        self._named: int | None = None
        """The track named the target (switched only on confirmation, :meth:`target_track`)."""
        self._named_once = False
        """Whether anyone was ever named (the hand-off is only for the start of a run)."""
        self._first_frame = math.inf
        """The stamp of the first camera frame (the hand-off's window starts there)."""
        self._near_seen: set[int] = set()
        """The tracks within ``handoff_range`` of the camera since the first frame
        (:meth:`_hand_off`)."""
        self._last_frame = -math.inf
        """The stamp of the newest camera frame observed."""
        self._apart: set[int] = set()
        """Tracks known to be other people than the named track since it was named — tracked
        at least ``coexist_distance`` from it, or seen by the camera beside it in one frame
        (not a split of her track): one of them coming close may be swapped with her
        (:meth:`_note_crossing`)."""
        self._apart_of: int | None = None
        """The named track ``_apart`` is about."""
        self._look_alike_at = -math.inf
        """When a person in her clothes was last found not to be her (by face, or seen beside
        her or where she cannot have been, or linked to someone who was)."""
        self._hers: set[int] = set()
        """Every track ever named the target."""
        self._dressed: dict[int, tuple[tuple[float, float], float]] = {}
        """Every track whose clothes matched hers, where and when the camera last saw it so."""
        self._held: dict[int, tuple[tuple[float, float], float]] = {}
        """Where and when the tracker last detected each track (:meth:`note_tracks`)."""
        self._her_at: tuple[tuple[float, float], float] | None = None
        """Where and when the tracker last detected the named track (:meth:`_note_out_of_reach`)."""
        self._astray: set[int] = set()
        """Tracks detected where she cannot have been (:meth:`_note_out_of_reach`)."""
        self._dropped: tuple[_Evidence, float] | None = None
        """The evidence of the track that last held the name when the name went on doubt or
        the tracker deleted it, and when (:meth:`_took_her_on`)."""
        self._crossed: tuple[float, dict[int, tuple[_Evidence, int]]] | None = None
        """When a passer-by in other clothes last crossed her named track out of the camera's
        view, and the two tracks, each with its number of clothes samples then
        (:meth:`_after_crossing`)."""
        self._crowded: set[int] = set()
        """Tracks with another person within ``update_clearance`` (at the latest
        :meth:`note_tracks`)."""
        self._online: tuple[np.ndarray, np.ndarray] | None = None
        """Her clothing histograms as learned online (item 5), None until learned."""

    @property
    def searches_faces(self) -> bool:
        """Whether faces are searched at all (inline or in a worker)."""
        return self.encoder is not None or self.worker is not None

    @property
    def pending(self) -> int:
        """Face searches out at the worker (submitted, not folded in yet)."""
        return len(self._jobs)

    def observe(
        self,
        track_id: int,
        t: float,
        has_legs: bool,
        detection: PersonDetection | None,
        rgb: np.ndarray | None,
        appearance: Appearance | None = None,
    ) -> TrackIdentity:
        """Add one observation of ``track_id`` at time ``t``; the updated identity. Pass
        ``appearance`` when it is already measured (else it is measured from ``rgb``; its face
        is then searched only when due)."""
        if appearance is not None and detection is not None:
            self.update(t)
            self._last_frame = max(self._last_frame, t)
            ev = self._observed(track_id, t, has_legs, detection)
            self._add_clothes(ev, appearance, t)
            if appearance.face is not None and self.searches_faces:
                self._fold_face(ev, t, appearance.face, appearance.face_box, t)
            identity = self._identify(track_id, ev, t)
            self._name(t)
            return identity
        return self.observe_frame(t, rgb, [(track_id, has_legs, detection)])[0]

    def observe_frame(
        self,
        t: float,
        rgb: np.ndarray | None,
        sightings: Sequence[tuple[int, bool, PersonDetection | None]],
        *,
        near: Collection[int] = (),
    ) -> list[TrackIdentity]:
        """Add one observation per ``(track_id, has_legs, detection)`` of the frame ``rgb``
        stamped ``t`` (detection None: the camera did not see that track); the updated
        identities, in order. Face searches that are due go to the tracks searched longest ago
        first (they matter when a worker has few slots). ``near``: the tracks within
        ``handoff_range`` of the camera now, seen by it or hidden (:meth:`_hand_off`)."""
        self.update(t)
        self._first_frame = min(self._first_frame, t)
        self._last_frame = max(self._last_frame, t)
        seen: list[tuple[int, _Evidence, PersonDetection | None]] = []
        for track_id, has_legs, detection in sightings:
            seen.append((track_id, self._observed(track_id, t, has_legs, detection), None))
        if rgb is not None:
            converted = None
            for k, (track_id, ev, _) in enumerate(seen):
                detection = sightings[k][2]
                if detection is None:
                    continue
                seen[k] = (track_id, ev, detection)
                if not self._clothes_due(ev, t):
                    self.face_stats.clothes_skipped += 1
                    continue
                if converted is None:
                    converted = convert(rgb, self.params.clothes.color_space)
                measured = len(ev.clothes)
                self._add_clothes(ev, describe(rgb, detection, self.params, None, converted), t)
                ev.last_clothes = t
                self.face_stats.clothes_measured += 1
                if len(ev.clothes) > measured and not _overlapped(detection, sightings):
                    ev.clear_clothes.append(ev.clothes_relit[-1])
            wanted = [
                (ev.last_search, k)
                for k, (_, ev, detection) in enumerate(seen)
                if detection is not None and self._face_due(ev, t)
            ]
            for _, k in sorted(wanted):
                track_id, ev, detection = seen[k]
                assert detection is not None
                region = face_region(detection, rgb.shape)
                if region is not None:
                    self._search(track_id, ev, t, rgb, region)
        self._hand_off(t, near)
        if self._named is not None and self._named == self._apart_of:
            ids = {track_id for track_id, _, detection in seen if detection is not None}
            if self._named in ids:  # people the camera sees beside her at once are others
                self._apart |= ids - {self._named}
        identities = [self._identify(track_id, ev, t) for track_id, ev, _ in seen]
        self._name(t)
        return identities

    def update(self, t: float) -> None:
        """Fold in the worker's results that count at ``t`` (``face_timing``); nothing without
        a worker. Called by every observation; call it when a frame shows nobody, too."""
        if self.worker is None or not self._jobs:
            return
        for result in self.worker.poll():
            if result.job in self._jobs:  # not another identifier's
                self._arrived[result.job] = result  # type: ignore[index]
        if self.params.timing == "deterministic":
            due = [j for j in self._jobs.values() if j.due <= t + STAMP_EPS]
            for job in due:
                result = self._arrived.pop(job.job, None)
                if result is None:
                    t0 = time.perf_counter()
                    result = self.worker.wait(job.job)
                    self.face_stats.waited_s += time.perf_counter() - t0
                self._finish(job, result, t)
        else:
            arrived, self._arrived = self._arrived, {}
            for job_id, result in arrived.items():
                job = self._jobs.get(job_id)
                if job is not None:
                    self._finish(job, result, t)

    def close(self) -> None:
        """Close the face worker (if one was given); safe to call twice."""
        if self._given_worker is not None:
            self._given_worker.close()
        self._jobs.clear()
        self._arrived.clear()

    # -- internals ----------------------------------------------------------------------------

    def _observed(
        self, track_id: int, t: float, has_legs: bool, detection: PersonDetection | None
    ) -> _Evidence:
        ev = self._tracks.setdefault(track_id, _Evidence())
        ev.observations += 1
        ev.last_seen = t
        ev.legs_seen += bool(has_legs)
        if detection is not None:
            ev.xy = (float(detection.position[0]), float(detection.position[1]))
            if ev.first_xy is None:
                ev.first_xy, ev.first_detected = ev.xy, t
            ev.last_detected = t
            self.distractors.seen(track_id, ev.xy, t)
        return ev

    def _add_clothes(self, ev: _Evidence, appearance: Appearance, t: float) -> None:
        s = self.profile.similarity(appearance)
        if s is None:
            return
        relit = self.profile.similarity(appearance, relit=True)
        assert relit is not None
        if self._online is not None:
            clothes = self.profile.clothes
            online = clothes_similarity(appearance, self._online, clothes)
            online_relit = clothes_similarity(appearance, self._online, clothes, relit=True)
            s = s if online is None else max(s, online)
            relit = relit if online_relit is None else max(relit, online_relit)
        first = not ev.clothes
        if not first and t - ev.last_clothes >= BACK_GAP_S - STAMP_EPS and self._is_named(ev):
            # back in view: the tracker may have carried her track onto someone else meanwhile
            # (traced, the crowd, seed 13: it coasted out of view onto a passer-by and came
            # back in his clothes, S 0.00, her clothes still the median of its newest five
            # samples for 0.2 s — a switch); it is judged on what it shows from now on
            ev.back_at = len(ev.clothes)
        ev.last_clothes = t
        ev.clothes.append(s)
        ev.clothes_relit.append(max(s, relit))
        ev.upper = appearance.upper if appearance.upper is not None else ev.upper
        ev.lower = appearance.lower if appearance.lower is not None else ev.lower
        if first and ev.xy is not None and ev.distractor is None:
            self._link(ev, t)
        elif ev.distractor is not None:
            self._check_slid_off_distractor(ev, appearance)

    def _is_named(self, ev: _Evidence) -> bool:
        """Whether ``ev`` is the evidence of the named track."""
        return self._named is not None and ev is self._tracks.get(self._named)

    def _check_slid_off_distractor(self, ev: _Evidence, appearance: Appearance) -> None:
        """A track known not to be her without a face (``coexisted``, ``linked``) whose clothes
        now match hers and are unlike the remembered distractor's under every light has slid
        onto someone else: the tracker carried the distractor's coasting track onto a person in
        her clothes (traced, the shipped house, seed 44: an extra's track, out of the camera's
        view in the office, took her detections behind the bookshelf; it ended there, and her
        new track was linked to the extra's memory by place, so she stayed "not her" 1 m from
        the robot to the end). The mark, the memory and the faces the track had are the other
        person's: all are forgotten. Who the track follows now is not known: her, or a
        look-alike the coasting track met (traced, the crowd, seed 14: a walker's mark slid onto
        a look-alike, who was then named on her clothes). So her clothes are no evidence on it,
        as while a look-alike is about: only a face names it, and it is someone to go and see —
        unless it took her on from her named track with every look-alike accounted for
        elsewhere (:meth:`_took_her_on`)."""
        p = self.params
        clothes = ev.clothes_now(p.clothes_recent)
        if clothes is None or clothes < p.clothes_similarity:
            return
        track_id = next(k for k, v in self._tracks.items() if v is ev)
        known = self.distractors.people.get(track_id)
        if known is None or known.upper is None or known.lower is None:
            return
        theirs = clothes_similarity(appearance, (known.upper, known.lower), p.clothes, relit=True)
        if theirs is None or theirs >= p.clothes_similarity - p.clothes_margin:
            return
        self.distractors.forget(track_id)
        ev.distractor, ev.slid = None, True
        ev.face_distances.clear()
        ev.last_match = ev.last_face = -math.inf

    def _link(self, ev: _Evidence, t: float) -> None:
        """A new track first measured: is it a remembered distractor (item 4)?"""
        assert ev.xy is not None
        target = (self.profile.upper, self.profile.lower)
        known = self.distractors.link(ev.xy, t, ev.upper, ev.lower, target)
        if known is None:
            return
        track_id = next(k for k, v in self._tracks.items() if v is ev)
        self.distractors.forget(known.track_id)
        self.distractors.remember(track_id, ev.xy, t, known.why, known.upper, known.lower)
        ev.distractor = "linked"

    def _clothes_due(self, ev: _Evidence, t: float) -> bool:
        """Whether the track's clothes (Algorithm 2's histogram intersection) should be
        measured in the frame stamped ``t``: always until its clothes evidence is settled, then
        every ``clothes_recheck_s`` (module docstring); the named track's always."""
        p = self.params
        if len(ev.clothes) < p.clothes_settled or t - ev.last_clothes >= (
            p.clothes_recheck_s - STAMP_EPS
        ):
            return True
        if self._is_named(ev):
            return True  # hers: a slide onto someone else shows within a few frames
        crossed = self._crossed
        if (
            crossed is not None
            and t - crossed[0] <= CROSSED_S + STAMP_EPS
            and any(ev is mine for mine, _ in crossed[1].values())
        ):
            return True  # one of the two who just crossed: her clothes show which is her
        if ev.face_distances:  # a face decides; clothes do not enter the decision
            return False
        clothes = ev.clothes_now(p.clothes_recent)
        return clothes is None or abs(clothes - p.clothes_similarity) < p.clothes_margin

    def _face_due(self, ev: _Evidence, t: float) -> bool:
        """Whether the track's face should be searched in the frame stamped ``t``."""
        p = self.params
        if not self.searches_faces or ev.job is not None:
            return False
        settled = len(ev.face_distances) >= p.face_settled
        if settled and t - ev.last_face < p.face_recheck_s - STAMP_EPS:
            return False
        if ev.face_misses >= p.face_miss_limit and (
            t - ev.last_search < p.face_miss_backoff_s - STAMP_EPS
        ):
            self.face_stats.backed_off += 1
            return False
        return True

    def _search(self, track_id: int, ev: _Evidence, t: float, rgb: np.ndarray, region: Box) -> None:
        """Search ``region`` for the track's face: inline now, or submitted to the worker."""
        if self.worker is None:
            assert self.encoder is not None
            ev.last_search = t
            self.face_stats.inline += 1
            self._fold_faces(ev, t, self.encoder.detect(rgb, region), t)
            return
        if self.params.timing == "deterministic" and len(self._jobs) >= (self.worker.max_in_flight):
            self.face_stats.deferred += 1
            return
        job = (self._key, self._next_job)
        if not self.worker.submit(job, rgb, region):
            self.face_stats.refused += 1
            if self.params.timing == "realtime":
                return  # busy: the track is tried again on a later frame
            # deterministic: only someone else's jobs can fill the worker; wait for a slot
            self.worker.wait_slot()
            if not self.worker.submit(job, rgb, region):  # pragma: no cover - cannot happen
                raise RuntimeError("face worker refused a job with a free slot")
        self._next_job += 1
        self.face_stats.submitted += 1
        ev.last_search = t
        ev.job = job
        due = t + self.params.face_latency_s
        self._jobs[job] = _Job(job, track_id, ev, t, due)

    def _finish(self, job: _Job, result: FaceResult, now: float) -> None:
        """A worker result: into its track's evidence, unless the track was deleted."""
        del self._jobs[job.job]
        job.evidence.job = None
        if self._tracks.get(job.track_id) is not job.evidence:
            self.face_stats.discarded += 1
            return
        self.face_stats.folded += 1
        self._fold_faces(job.evidence, job.stamp, result.faces, now)
        self._identify(job.track_id, job.evidence, now)

    def _fold_faces(self, ev: _Evidence, stamp: float, faces: Sequence[Face], now: float) -> None:
        """The outcome of one face search of the frame stamped ``stamp`` (best face first)."""
        if faces:
            self._fold_face(ev, stamp, faces[0].embedding, faces[0].box, now)
        else:
            ev.face_misses += 1

    def _fold_face(
        self, ev: _Evidence, stamp: float, embedding: np.ndarray, box: Box | None, now: float
    ) -> None:
        if box is not None and box[3] - box[1] < self.params.min_face_px:
            self.face_stats.too_small += 1  # too far to tell: neither a match nor a mismatch
            return
        d = self.profile.face_distance(embedding)
        if d is None:
            return
        ev.face_distances.append(d)
        if d < self.params.face_distance:
            ev.last_match = max(ev.last_match, stamp)
        ev.last_face = max(ev.last_face, stamp)
        ev.face_misses = 0
        ev.face_box, ev.face_box_at = box, now

    def _identify(self, track_id: int, ev: _Evidence, now: float) -> TrackIdentity:
        """The track's identity now (and remembered as its latest)."""
        box = ev.face_box if ev.face_box_at == now else None
        identity = self._decide(track_id, ev, box)
        self._latest[track_id] = identity
        return identity

    def _decide(self, track_id: int, ev: _Evidence, face_box: Box | None) -> TrackIdentity:
        p = self.params
        clothes = ev.clothes_now(p.clothes_recent)
        relit = ev.relit_now(p.clothes_recent)
        now = ev.last_seen
        self._check_unlike(ev, relit, now)  # before the faces: it may forget them
        self._check_turned_hers(track_id, ev)
        face_d = ev.face(p.face_recent)
        best = min(ev.face_distances) if ev.face_distances else None
        if face_d is not None and face_d >= p.face_distance:
            self._rejected_by_face(track_id, ev, clothes, now)
        elif face_d is not None and track_id in self.distractors.people:
            self.distractors.forget(track_id)  # her face: a wrong link or mark
            ev.distractor = None
        if ev.distractor is not None and clothes is not None and clothes >= p.clothes_similarity:
            self._look_alike_at = max(self._look_alike_at, now)  # someone else in her clothes
        elif track_id in self._astray and self._dressed_now(ev):
            self._look_alike_at = max(self._look_alike_at, now)  # in her clothes where she is not
        if clothes is not None and clothes >= p.clothes_similarity and ev.xy is not None:
            self._dressed[track_id] = (ev.xy, ev.last_detected)
        look_alike = (ev.slid or self._look_alike_about(track_id, now)) and not (
            self._took_her_on(track_id, now)
        )
        cues = Cues(
            face_distance=face_d,
            clothes_similarity=clothes,
            clothes_relit=relit,
            look_alike_about=look_alike,
            distractor=ev.distractor is not None,
            named=track_id == self._named,
        )
        lo, basis = log_odds(cues, p.weights, p.face_distance, p.clothes_similarity)
        if ev.legs_seen == 0 and lo > -p.weights.reject:
            # legs first (Algorithm 2): no legs, not a person she can be — but whoever is not
            # her, person or coat, is not her (traced, the house, seed 45: a passer-by the
            # camera alone tracked stayed unknown and drew the gaze from her for 10 s)
            decision, conf, basis = Decision.UNKNOWN, 0.0, "no_legs"
        elif lo >= p.weights.accept:
            decision, conf = Decision.TARGET, 1.0 / (1.0 + math.exp(-lo))
        elif lo <= -p.weights.reject:
            decision, conf = Decision.NOT_TARGET, 1.0 / (1.0 + math.exp(lo))
        else:
            decision, conf = Decision.UNKNOWN, 0.0
        if decision is Decision.TARGET:
            ev.streak_since = min(ev.streak_since, now) if ev.streak else now
            ev.streak += 1
            ev.below_since = math.inf
        else:
            ev.streak, ev.streak_since = 0, math.inf
            ev.below_since = min(ev.below_since, now)
        return TrackIdentity(
            track_id=track_id,
            decision=decision,
            confidence=conf,
            basis=basis,
            face_distance=face_d,
            best_face_distance=best,
            clothes_similarity=clothes,
            clothes_relit=relit,
            face_samples=len(ev.face_distances),
            clothes_samples=len(ev.clothes),
            observations=ev.observations,
            legs_seen=ev.legs_seen,
            last_seen=ev.last_seen,
            face_box=face_box,
            log_odds=lo,
        )

    def _check_unlike(self, ev: _Evidence, clothes: float | None, now: float) -> None:
        """A track whose clothes turn clearly unlike hers (``clothes``: the relit similarity,
        ``clothes_margin`` below the threshold) has slid onto someone else (the tracker swapped
        it in a crowd): the faces of hers it showed before are not this person's, so they are
        forgotten, and a name it holds goes at once unless her face is seen on it again
        (:meth:`_doubted`)."""
        p = self.params
        unlike = clothes is not None and clothes < p.clothes_similarity - p.clothes_margin
        if not unlike:
            ev.unlike_since = math.inf
            return
        ev.unlike_until = now
        if math.isfinite(ev.unlike_since):
            return
        ev.unlike_since = now
        if math.isfinite(ev.last_match):
            ev.face_distances.clear()
            ev.last_match = ev.last_face = -math.inf

    def _check_turned_hers(self, track_id: int, ev: _Evidence) -> None:
        """A track whose clothes were clearly unlike hers and now show hers (:meth:`_dressed_now`),
        and whose faces, none seen since they were unlike, were none of them hers, has slid onto
        someone in her clothes: the tracker swapped two tracks as two people crossed. The faces
        it showed are the other person's, so they are forgotten, and so is the memory of them as
        a person rejected by face — the mirror of :meth:`_check_unlike`. A track that showed her
        face keeps it: her face decides, whatever its clothes measured then. Traced, the crowd,
        seed 16: a passer-by crossed her 2.4 s in; her named track took his legs (its clothes
        turned unlike hers, and the name went), and his track, rejected by his face (0.86), took
        hers. His face kept her track "not her", and, on a track in her clothes, said that a
        look-alike was about, so her clothes counted for no one for two minutes. Who the track
        follows now is not known (her, or a look-alike it met), so, as after a slide off a
        distractor (:meth:`_check_slid_off_distractor`), her clothes name it only when it took
        her on from her named track (:meth:`_took_her_on`); else its face does, and until then
        it is someone to go and see."""
        if not ev.face_distances or math.isfinite(ev.last_match):
            return
        if ev.last_face > ev.unlike_until or not self._dressed_now(ev):
            return
        ev.face_distances.clear()
        ev.last_match = ev.last_face = -math.inf
        ev.slid = True
        known = self.distractors.people.get(track_id)
        if known is not None and known.why == "face":
            self.distractors.forget(track_id)

    def _dressed_now(self, ev: _Evidence) -> bool:
        """Whether a track shows her clothes now: its median and its newest sample match hers
        (a track that coasted onto a passer-by keeps her clothes in its median for a few
        frames, :meth:`_note_two_in_her_clothes`)."""
        p = self.params
        clothes = ev.clothes_now(p.clothes_recent)
        return (
            clothes is not None
            and clothes >= p.clothes_similarity
            and ev.clothes[-1] >= p.clothes_similarity
        )

    def _rejected_by_face(
        self, track_id: int, ev: _Evidence, clothes: float | None, now: float
    ) -> None:
        """A face not hers: remember the person (item 4); in her clothes, a look-alike is about."""
        if ev.xy is not None:
            self.distractors.remember(track_id, ev.xy, now, "face", ev.upper, ev.lower)
        if clothes is not None and clothes >= self.params.clothes_similarity:
            self._look_alike_at = max(self._look_alike_at, now)

    def _look_alike_about(self, track_id: int, now: float) -> bool:
        """Whether someone in her clothes other than ``track_id`` is about: another track now
        whose clothes match hers (not one this track picked up from, :meth:`_split`), or a
        person in her clothes found not to be her within ``look_alike_memory_s``."""
        p = self.params
        if now - self._look_alike_at <= p.look_alike_memory_s:
            return True
        ev = self._tracks.get(track_id)
        for tid, other in self._tracks.items():
            clothes = other.clothes_now(p.clothes_recent)
            if (
                tid != track_id
                and other.legs_seen
                and clothes is not None
                and clothes >= p.clothes_similarity
                and not (ev is not None and self._split(other, ev))
            ):
                return True
        return False

    def _split(self, old: _Evidence, new: _Evidence) -> bool:
        """Whether ``new`` may be the person of ``old`` picked up anew (the tracker lost her
        legs for a moment, or a camera-only track was made beside her coasting one — traced,
        the house, seed 40: her named track stopped at the kitchen door and a new one took her
        on): the camera first saw ``new`` at most :data:`SPLIT_GAP_S` after it last saw
        ``old``, within ``coexist_distance`` of the place, and has not seen ``old`` since. The
        two were never seen at once, so they are not two people in her clothes."""
        if old.xy is None or new.first_xy is None:
            return False
        gap = new.first_detected - old.last_detected
        return (
            -STAMP_EPS <= gap <= SPLIT_GAP_S
            and math.dist(old.xy, new.first_xy) < self.params.coexist_distance
        )

    def _name(self, t: float) -> None:
        """Who is the target after this observation (:meth:`_choose`); every track ever named
        is remembered as hers."""
        self._choose(t)
        if self._named is not None:
            self._hers.add(self._named)

    def _choose(self, t: float) -> None:
        """Who is the target after this observation (item 2): the named track while the tracker
        holds it and it is not decided NOT_TARGET (continuity); else the one track that took
        her on from it (:meth:`_took_her_on`) and is decided TARGET :data:`SPLIT_FRAMES` times
        in a row; else a track a face decides TARGET at once; else a track decided TARGET on
        ``confirm_frames`` identifications in a row over ``confirm_s`` (without a face that can
        only happen while no look-alike is about: her clothes are no evidence then; and with
        ``face_to_rename``, once she was named, only to a track that held her name,
        :meth:`_face_to_rename`); else no one — she is lost, and the robot searches."""
        named = self._latest.get(self._named) if self._named is not None else None
        doubted = named is not None and self._doubted(named, t)
        if named is not None and doubted:
            self._dropped = (self._tracks[named.track_id], t)
        if named is not None and not doubted:
            picked_up = self._picked_up(named.track_id, t)
            if picked_up is not None:
                self._named = picked_up
                return
            ev = self._tracks[self._named]
            fresher = self._fresher_face(self._named, max(ev.last_match, ev.first_detected))
            if fresher is None:
                self._learn_online(t)
                return
            self._named = fresher
            return
        took = [
            tid
            for tid, ident in self._latest.items()
            if tid != self._named
            and ident.decision is Decision.TARGET
            and self._tracks[tid].streak >= SPLIT_FRAMES
            and abs(self._tracks[tid].last_detected - t) <= STAMP_EPS
            and self._took_her_on(tid, t)
        ]
        if len(took) == 1:
            self._named = took[0]
            return
        best: tuple[tuple[int, float, float], int] | None = None
        for tid, ident in self._latest.items():
            if ident.decision is not Decision.TARGET:
                continue
            face = (
                ident.face_distance is not None and ident.face_distance < self.params.face_distance
            )
            ev = self._tracks[tid]
            if not face and (
                not self._confirmed(ev, t) or tid in self._astray or self._face_to_rename(tid)
            ):
                continue
            key = (int(face), ident.log_odds, ident.last_seen)
            if best is None or key > best[0]:
                best = (key, tid)
        self._named = None if best is None else best[1]
        self._named_once |= self._named is not None

    def _face_to_rename(self, track_id: int) -> bool:
        """Whether only her face can name ``track_id`` now (``face_to_rename``): she was named
        once (by the hand-off or after it), faces are searched, and the track never held her
        name. Someone in her clothes whom the robot has not seen yet may be about at any time,
        and once she is lost nothing but a face tells her from them."""
        return (
            self.params.face_to_rename
            and self._named_once
            and self.searches_faces
            and track_id not in self._hers
        )

    def _holder(self, now: float) -> _Evidence | None:
        """The evidence of the track that holds her name, or held it until at most
        :data:`SPLIT_GAP_S` ago (the name went on doubt, or the tracker deleted the track)."""
        if self._named is not None and self._named in self._tracks:
            return self._tracks[self._named]
        if self._dropped is not None and now - self._dropped[1] <= SPLIT_GAP_S + STAMP_EPS:
            return self._dropped[0]
        return None

    def _took_her_on(self, track_id: int, now: float) -> bool:
        """Whether ``track_id`` took her on from the track that holds (or just held) her name —
        picked up anew where that one was left (:meth:`_split`), swapped with it as the two
        passed (:meth:`_swapped`), or the one in her clothes of the two tracks of a crossing
        (:meth:`_after_crossing`) — while every other person in her clothes seen so far is
        accounted for elsewhere (:meth:`_look_alikes_elsewhere`). Such a track's clothes count
        for her though a look-alike is about: the look-alikes are known to be elsewhere, and the
        track holds her where her own track left her. Traced, the crowd, seed 7: her named
        track coasted off her course, a new track took her on where it had been, in her clothes
        (S 0.9), and stayed unknown because a look-alike, rejected 5 m away and tracked there,
        was about; seed 3: a passer-by crossing her took her track (its clothes turned unlike
        hers), and his own track took her on. She was lost both times, and not re-found in the
        minute."""
        new = self._tracks.get(track_id)
        if new is None or new.xy is None:
            return False
        old = self._holder(now)
        took = old is not None and (self._split(old, new) or self._swapped(old, new))
        if old is not None and old is not new and took:
            return self._look_alikes_elsewhere(track_id, new.xy, old, now)
        return self._after_crossing(track_id, new, now)

    def _after_crossing(self, track_id: int, new: _Evidence, now: float) -> bool:
        """Whether ``track_id`` is one of the two tracks of a crossing that took the name away
        (a passer-by in other clothes, her track out of the camera's view; at most
        :data:`CROSSED_S` ago) and has shown her clothes on its newest :data:`SPLIT_FRAMES`
        samples since, with every other person in her clothes accounted for elsewhere
        (:meth:`_look_alikes_elsewhere`): after two people in different clothes crossed, the
        one in hers is her. Traced, the crowd, seed 7: a passer-by stepped between the robot
        and her, 0.2 m from her, and the name went; her track showed her clothes (S 0.9) right
        after, and she stayed unknown until the search."""
        if self._crossed is None or now - self._crossed[0] > CROSSED_S + STAMP_EPS:
            return False
        partners = self._crossed[1]
        mine = partners.get(track_id)
        if mine is None or mine[0] is not new:
            return False
        fresh = new.clothes[mine[1] :][-SPLIT_FRAMES:]
        if len(fresh) < SPLIT_FRAMES or min(fresh) < self.params.clothes_similarity:
            return False
        other = next((ev for tid, (ev, _) in partners.items() if tid != track_id), new)
        assert new.xy is not None
        return self._look_alikes_elsewhere(track_id, new.xy, other, now)

    def _swapped(self, old: _Evidence, new: _Evidence) -> bool:
        """Whether the tracker swapped her track ``old`` with ``new`` as the two people passed:
        ``old``'s clothes turned clearly unlike hers (it slid onto the other person) within
        :data:`SPLIT_GAP_S` of when ``new``'s were last clearly unlike hers (it was the other
        person), ``new``'s match hers now, and the camera saw the two within
        ``coexist_distance`` of each other."""
        p = self.params
        if old.xy is None or new.xy is None or not math.isfinite(old.unlike_since):
            return False
        clothes = new.clothes_now(p.clothes_recent)
        return (
            clothes is not None
            and clothes >= p.clothes_similarity
            and abs(new.unlike_until - old.unlike_since) <= SPLIT_GAP_S
            and math.dist(old.xy, new.xy) < p.coexist_distance
        )

    def _look_alikes_elsewhere(
        self, track_id: int, xy: tuple[float, float], old: _Evidence, now: float
    ) -> bool:
        """Whether every other person in her clothes seen so far — a track whose clothes
        matched hers (none ever named her, nor ``old``), or a remembered distractor dressed like
        her or in clothes not known — was last seen (by the camera, or their track by the
        laser) so far from ``xy`` and so lately that they cannot be there now:
        ``coexist_distance`` plus :data:`LOOK_ALIKE_SPEED` m/s since."""
        reach = self.params.coexist_distance

        def could_be_here(tid: int, where: tuple[float, float], when: float) -> bool:
            held = self._held.get(tid)
            if held is not None and held[1] > when:
                where, when = held
            return math.dist(where, xy) < reach + LOOK_ALIKE_SPEED * max(0.0, now - when)

        for tid, (where, when) in self._dressed.items():
            if tid == track_id or tid in self._hers or self._tracks.get(tid) is old:
                continue
            if could_be_here(tid, where, when):
                return False
        target = (self.profile.upper, self.profile.lower)
        return not any(
            d.track_id != track_id
            and d.track_id not in self._hers
            and self.distractors.may_be_dressed_like(d, target)
            and could_be_here(d.track_id, (d.x, d.y), d.t)
            for d in self.distractors.people.values()
        )

    def _hand_off(self, t: float, near: Collection[int]) -> None:
        """The start of following (item 2's one exception): within ``handoff_s`` of the first
        frame and before anyone was named, the one person tracked within ``handoff_range`` of
        the camera, seen by it now — legs tracked, clothes matching hers, no face of someone
        else, not known to be someone else — is the person the robot was just shown (``pfctl
        learn-target``, then ``pfctl follow``), and is named at once, look-alikes about or not.
        From then on her track keeps the name on continuity, as any named track does: she can
        be followed from behind among look-alikes. A second person tracked that close at any
        time in the window (seen, or hidden behind another) who may be her too — not seen yet,
        or in her clothes — makes it ambiguous: no hand-off, and the usual rules name her (a
        face, or a confirmed identification). A passer-by in other clothes does not."""
        p = self.params
        late = t - self._first_frame > p.handoff_s + STAMP_EPS
        if p.handoff_s <= 0 or self._named_once or late:
            return
        self._near_seen.update(near)
        seen = [k for k in near if k in self._tracks and self._tracks[k].last_seen == t]
        hers = [k for k in seen if self._may_be_her(k)]
        if len(hers) != 1:
            return
        (track_id,) = hers
        ev = self._tracks[track_id]
        clothes = ev.clothes_now(p.clothes_recent)
        if not ev.legs_seen or clothes is None or clothes < p.clothes_similarity:
            return
        if any(k != track_id and self._may_be_her(k) for k in self._near_seen):
            return  # someone else near who may be her too (her clothes, or not seen yet)
        self._named, self._named_once = track_id, True
        self._hers.add(track_id)

    def _handoff_open(self) -> bool:
        """Whether the hand-off may still name her: it is on, nobody was named yet, and no
        camera frame has come ``handoff_s`` after the first (nor any frame at all)."""
        p = self.params
        if p.handoff_s <= 0 or self._named_once:
            return False
        if not math.isfinite(self._first_frame):
            return True
        return self._last_frame - self._first_frame <= p.handoff_s + STAMP_EPS

    def _may_be_her(self, track_id: int) -> bool:
        """Whether a track may be her as far as the hand-off knows: not known to be someone
        else — a distractor, a face not hers, or clothes not hers in the median of at least
        :data:`CLEAR_SAMPLES` samples taken while no one else overlapped the person in the image
        (traced, generated home 10: she stood hidden behind a look-alike, and the sliver of her
        the camera saw did not match her clothes)."""
        p = self.params
        ev = self._tracks.get(track_id)
        if ev is None:
            return True  # never seen by the camera, or gone: not known to be anyone else
        face = ev.face(p.face_recent)
        clear = ev.clear_clothes[-p.clothes_recent :]
        unlike = len(clear) >= CLEAR_SAMPLES and float(np.median(clear)) < p.clothes_similarity
        return not (
            ev.distractor is not None or (face is not None and face >= p.face_distance) or unlike
        )

    def _doubted(self, named: TrackIdentity, t: float) -> bool:
        """Whether the named track has lost the name: decided NOT_TARGET; its clothes clearly
        unlike hers with no face of hers seen since (:meth:`_check_unlike`); or below TARGET
        (a face that does not quite match, clothes that stopped matching) for ``doubt_s``."""
        if named.decision is Decision.NOT_TARGET:
            return True
        ev = self._tracks[named.track_id]
        if ev.last_match < ev.unlike_since < math.inf:
            return True  # clothes clearly unlike hers, no face of hers since: slid off her
        return t - ev.below_since >= self.params.doubt_s - STAMP_EPS

    def _confirmed(self, ev: _Evidence, t: float) -> bool:
        """Whether a track at TARGET without a face has been so long enough to be named:
        ``confirm_frames`` identifications in a row over at least ``confirm_s``."""
        p = self.params
        return ev.streak >= p.confirm_frames and t - ev.streak_since >= p.confirm_s - STAMP_EPS

    def _picked_up(self, named: int, t: float) -> int | None:
        """The one track that took her on from the ``named`` one (:meth:`_split`), seen in this
        frame and decided TARGET :data:`SPLIT_FRAMES` times in a row (her clothes, no look-alike
        about, no face of someone else): the name follows her (issue 23, item 1: continuity is
        the person's, not the track number's). None when there is none, or more than one."""
        old = self._tracks[named]
        found = [
            tid
            for tid, ident in self._latest.items()
            if tid != named
            and ident.decision is Decision.TARGET
            and self._tracks[tid].streak >= SPLIT_FRAMES
            and abs(self._tracks[tid].last_detected - t) <= STAMP_EPS
            and self._split(old, self._tracks[tid])
        ]
        return found[0] if len(found) == 1 else None

    def _fresher_face(self, named: int | None, since: float) -> int | None:
        """A track other than ``named`` that a face decides TARGET with a face match newer than
        ``since`` by ``face_recheck_s`` or more (the named track's evidence is older: the tracker
        may have swapped it onto someone else); the newest such match first. ``since`` is the
        named track's newest face match, or its first sighting if later: a face another track
        showed before the named one was seen at all says nothing about which is her now (the
        track she was picked up from, :meth:`_picked_up`)."""
        best: tuple[float, int] | None = None
        for tid, ident in self._latest.items():
            ev = self._tracks[tid]
            if (
                tid != named
                and ident.decision is Decision.TARGET
                and ident.face_distance is not None
                and ident.face_distance < self.params.face_distance
                and ev.last_match >= since + self.params.face_recheck_s
                and (best is None or ev.last_match > best[0])
            ):
                best = (ev.last_match, tid)
        return None if best is None else best[1]

    def _learn_online(self, t: float) -> None:
        """Fold the named track's clothes of this frame into her online appearance model — only
        when a face confirms the track and no other person is within ``update_clearance``
        (item 5: the model must not learn a look-alike standing beside her)."""
        p = self.params
        ev = self._tracks.get(self._named) if self._named is not None else None
        if ev is None or p.update_rate <= 0 or self._named in self._crowded:
            return
        face = ev.face(p.face_recent)
        if face is None or face >= p.face_distance:
            return
        if abs(ev.last_clothes - t) > STAMP_EPS or ev.upper is None or ev.lower is None:
            return
        if self._online is None:
            self._online = (self.profile.upper.copy(), self.profile.lower.copy())
        r = p.update_rate
        upper = (1 - r) * self._online[0] + r * ev.upper
        lower = (1 - r) * self._online[1] + r * ev.lower
        self._online = (upper / upper.sum(), lower / lower.sum())

    @property
    def online_appearance(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Her upper and lower clothing histograms as learned online (None: not learned yet)."""
        return self._online

    def note_tracks(self, t: float, tracks: Sequence[tuple[int, float, float, bool]]) -> None:
        """The tracker's people now, ``(track_id, x, y, detected)`` (detected: not coasting).

        While the named target is confirmed by her face and detected, every other detected
        track at least ``coexist_distance`` from her is someone else (two places at once) and
        is marked so — a face match of its own is the only way back (item 1). Which tracks have
        another person within ``update_clearance`` is kept for the online appearance model
        (item 5), and where each detected track is, for :meth:`_look_alikes_elsewhere`."""
        p = self.params
        xy = {tid: (x, y) for tid, x, y, _ in tracks}
        self._held.update({tid: ((x, y), t) for tid, x, y, detected in tracks if detected})
        self._crowded = {
            a
            for a, (ax, ay) in xy.items()
            if any(
                b != a and math.hypot(ax - bx, ay - by) < p.update_clearance
                for b, (bx, by) in xy.items()
            )
        }
        self._note_two_in_her_clothes(t, tracks)
        self._note_out_of_reach(t, tracks)
        self._note_crossing(t, xy)
        her = self._named
        ev = self._tracks.get(her) if her is not None else None
        if her is None or ev is None or her not in xy:
            return
        face = ev.face(p.face_recent)
        if face is None or face >= p.face_distance:
            return
        if not any(tid == her and detected for tid, _, _, detected in tracks):
            return
        hx, hy = xy[her]
        for tid, x, y, detected in tracks:
            if tid == her or not detected or math.hypot(x - hx, y - hy) < p.coexist_distance:
                continue
            other = self._tracks.setdefault(tid, _Evidence())
            if other.distractor is None and not other.face_distances:
                other.distractor = "coexisted"
            if other.distractor is not None:
                self.distractors.remember(tid, (x, y), t, "coexisted", other.upper, other.lower)

    def _note_crossing(self, t: float, xy: dict[int, tuple[float, float]]) -> None:
        """Another person comes within ``swap_distance`` of her named track — someone tracked
        at least ``coexist_distance`` from it or seen by the camera beside it before, not a
        split of her own track — where the camera cannot tell the two apart: the other is in
        her clothes, or her track was not in the camera's last frame. The tracker may swap two
        people as they cross (traced: a look-alike crossing her, and her track coasting out of
        view onto a passer-by's legs), so which track is her is not known any more: the name
        goes (she is lost rather than someone else followed), and both tracks forget the faces
        and the run of identifications they had (they may be the other person's). A face, a
        confirmed identification, or — when the other was in other clothes — her clothes on one
        of the two afterwards (:meth:`_after_crossing`) names her again."""
        her = self._named
        if her != self._apart_of:
            self._apart, self._apart_of = set(), her
        if her is None or her not in xy:
            return
        p = self.params
        ev = self._tracks.get(her)
        unseen = ev is None or ev.last_seen < self._last_frame - STAMP_EPS
        hx, hy = xy[her]
        for tid, (x, y) in xy.items():
            gap = math.hypot(x - hx, y - hy)
            if tid == her:
                continue
            if gap >= p.coexist_distance:
                self._apart.add(tid)
                continue
            if gap >= p.swap_distance or tid not in self._apart:
                continue
            other = self._tracks.get(tid)
            clothes = None if other is None else other.clothes_now(p.clothes_recent)
            dressed = clothes is not None and clothes >= p.clothes_similarity
            if unseen or dressed:
                self._named = None
                for track_id in (her, tid):
                    self._forget_who(track_id)
                if not dressed and ev is not None and other is not None:
                    self._crossed = (
                        t,
                        {her: (ev, len(ev.clothes)), tid: (other, len(other.clothes))},
                    )
                return

    def _note_out_of_reach(
        self, t: float, tracks: Sequence[tuple[int, float, float, bool]]
    ) -> None:
        """Where she can be (issue 23, item 1: track continuity and where she can have walked):
        the named track's latest detected place is remembered, and every other track detected
        farther from it than she can have walked since — ``coexist_distance`` plus
        :data:`LOOK_ALIKE_SPEED` m/s — is someone else, and is not named on clothes alone
        (:meth:`_choose`) nor gone to see (:meth:`candidate_track`); shown in her clothes
        there, a look-alike is about (:meth:`_decide`). Traced, the crowd, seed 27:
        3.1 s after her track was lost, a track in her clothes 8.2 m from where it was lost was
        confirmed on clothes alone, and followed. Before anyone is named nothing is known of where
        she is, and after a long loss she can be anywhere: the mark then never happens."""
        her = self._named
        for tid, x, y, detected in tracks:
            if tid == her and detected:
                self._her_at = ((x, y), t)
        if self._her_at is None:
            return
        (hx, hy), when = self._her_at
        reach = self.params.coexist_distance + LOOK_ALIKE_SPEED * max(0.0, t - when)
        for tid, x, y, detected in tracks:
            if tid != her and detected and math.hypot(x - hx, y - hy) > reach:
                self._astray.add(tid)

    def _forget_who(self, track_id: int) -> None:
        """Forget what said who a track is: its faces and its run of identifications (the
        tracker may have swapped it onto someone else, :meth:`_note_crossing`)."""
        ev = self._tracks.get(track_id)
        if ev is None:
            return
        ev.face_distances.clear()
        ev.last_match = ev.last_face = -math.inf
        ev.streak, ev.streak_since = 0, math.inf
        self._astray.discard(track_id)
        if track_id in self._latest:
            self._latest[track_id] = self._decide(track_id, ev, None)

    def _note_two_in_her_clothes(
        self, t: float, tracks: Sequence[tuple[int, float, float, bool]]
    ) -> None:
        """Two people in her clothes at least ``coexist_distance`` apart at once: one
        of them at most is her, so a look-alike is about — remembered for
        ``look_alike_memory_s``, as a look-alike rejected by face is, so that when one of the two
        is lost the other is not named on her clothes alone (item 2). Only people whose clothes
        the camera measured within :data:`FRESH_CLOTHES_S` count (a track's old samples may be
        of someone else), whether the laser sees them or not (a track the camera alone sees
        coasts between the laser's scans): at worst her clothes are no evidence for a while,
        which loses her rather than following someone else. The newest sample must match too:
        a track that coasted onto a passer-by keeps her clothes in its median for a few frames
        (traced, the house, seed 40: her old track slid onto bob at the kitchen door, and her
        clothes were no evidence for the rest of the episode). Nor are two tracks of one person
        two people (:meth:`_split`)."""
        p = self.params
        dressed: list[tuple[_Evidence, float, float]] = []
        for tid, x, y, _ in tracks:
            ev = self._tracks.get(tid)
            if ev is None:
                continue
            if self._dressed_now(ev) and t - ev.last_clothes <= FRESH_CLOTHES_S + STAMP_EPS:
                dressed.append((ev, x, y))
        if any(
            math.hypot(ax - bx, ay - by) >= p.coexist_distance
            and not self._split(a, b)
            and not self._split(b, a)
            for (a, ax, ay), (b, bx, by) in itertools.combinations(dressed, 2)
        ):
            self._look_alike_at = max(self._look_alike_at, t)

    def identity(self, track_id: int) -> TrackIdentity | None:
        """The latest identity of a track (None if never observed or forgotten)."""
        return self._latest.get(track_id)

    def identities(self) -> dict[int, TrackIdentity]:
        """The latest identity of every known track."""
        return dict(self._latest)

    def target_track(self) -> int | None:
        """The track named the target (:meth:`_name`: kept while the tracker holds it, switched
        only on a face match or a confirmed identification); None: she is lost."""
        return self._named if self._named in self._latest else None

    def candidate_track(self) -> int | None:
        """An ambiguous person worth going to see the face of (issue 23, item 3): a track, not
        named, not decided NOT_TARGET, not known to be someone else, its face not yet seen,
        whose clothes match hers under this light or another (the relit similarity; so only a
        face can tell: a look-alike may be about, it is not confirmed yet, or the light is not
        the one she was learned in), with legs — or, seen by the camera alone (beyond the
        laser's legs, 6 m), in her clothes under this light (traced, generated home 41: she
        stood 8 m off in the bedroom, S = 0.78, and the search went on to the study). The most
        recently seen first. None when she is named, or no one is ambiguous, or while the
        hand-off may still name her (:meth:`_hand_off`: the robot does not drive up to the
        person it is being shown; traced, house seeds 27 and 48: the search drove toward her at
        0.1 s, before the hand-off named her at 0.2 s)."""
        if self.target_track() is not None or self._handoff_open():
            return None
        p = self.params
        best: tuple[float, int] | None = None
        for tid, ident in self._latest.items():
            ev = self._tracks[tid]
            if (
                ident.decision is not Decision.NOT_TARGET
                and (ident.legs_seen or self._dressed_as_her(ident))
                and not ev.face_distances
                and ev.distractor is None
                and tid not in self._astray
                and ident.clothes_relit is not None
                and ident.clothes_relit >= p.clothes_similarity
                and (best is None or ident.last_seen > best[0])
            ):
                best = (ident.last_seen, tid)
        return None if best is None else best[1]

    def _dressed_as_her(self, ident: TrackIdentity) -> bool:
        """Whether a track's clothes match hers under this light (the plain similarity)."""
        s = ident.clothes_similarity
        return s is not None and s >= self.params.clothes_similarity

    def known_tracks(self) -> set[int]:
        """The tracks the identifier holds anything about (to :meth:`forget` when deleted)."""
        return set(self._tracks) | set(self._latest)

    def forget(self, track_id: int) -> None:
        """Drop a track's evidence (the tracker deleted it); a distractor stays remembered."""
        ev = self._tracks.pop(track_id, None)
        self._latest.pop(track_id, None)
        self._astray.discard(track_id)
        self.distractors.track_ended(track_id)
        if self._named == track_id:
            self._named = None
            if ev is not None:
                self._dropped = (ev, self._last_frame)


__all__ = ["Decision", "FaceSearchStats", "TargetIdentifier", "TrackIdentity"]
