"""Learning what the target looks like (§II-E): the procedures behind ``pfctl learn-target``
and behind ``pfctl follow``/``search``/``bench`` when they learn the target first.

Each gathers :class:`~pfctl.core.perception.identity.profile.Appearance` values (the clothing
histograms in the mission's ``perception.identity`` colour space and bins, the face
embeddings) into a :class:`Learned`; :func:`~pfctl.core.perception.identity.profile.learn_profile`
turns them into the target's profile. Three sources:

- :func:`learn_in_sim`: the scenario's target stands ~1.4 m in front of the simulated robot,
  facing it and turning a little from side to side; the robot turns its head to them and nods
  between their face and their legs, so it sees both, for ``seconds`` simulated seconds. Frames
  from the simulated camera go through the mask person detector (the simulator's stand-in for
  OpenPose); the person is the detection nearest the spot they were asked to stand on, as a
  person on a real robot would be asked to stand in front of it.
- :func:`learn_on_robot` (:func:`learn_on_hsr` for the Toyota HSR over ROS 1, or the simulated
  house served by ``pfctl sim serve-hsr --pose-target``): the person stands
  :data:`STAND_DISTANCE` m straight in front of the robot, which stands still and nods its head
  between a face and a body height for ``seconds`` of the robot's clock; detections come from
  the mission's ``backend.hsr.person_labels`` (or ``person_keypoints``).
- :func:`learn_from_images`: a folder of images (``.png``, ``.jpg``, ...), one image, or a video
  file (at most :data:`MAX_VIDEO_FRAMES` frames, evenly spaced) of the person, read with OpenCV.
  Each image is searched with OpenCV's HOG people detector. When it finds nobody and the image
  is portrait (height ≥ 1.5 × width), the image is taken as a crop of one person; otherwise the
  image is skipped (OpenCV 5.0 has no HOG detector: then every image is taken whole as a crop
  of one person). Where it finds several people, ``pick`` takes the N-th from the left
  (1 = leftmost); without it that is an error listing what was seen.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from rich.progress import Progress

from pfctl.core.perception.faces import FaceEncoder
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import (
    Appearance,
    describe,
)
from pfctl.core.perception.vision import (
    HogPersonDetector,
    PersonDetection,
    PersonDetector,
    hog_available,
)
from pfctl.core.robot import STOP, HeadTarget, Pose2D, RgbdFrame, Robot
from pfctl.errors import UserError
from pfctl.mission import Mission

if TYPE_CHECKING:
    from pfctl.backends.pybullet.simulation import SimRobot
    from pfctl.core.mapping.planning import GridPlanner

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".ppm", ".pgm")
#: Frames read from a video at most (evenly spaced over it).
MAX_VIDEO_FRAMES = 60
#: Where the target is asked to stand, metres in front of the robot (sim).
STAND_DISTANCE = 1.4
#: How long (simulated s) the target waits for other people to walk off the spots in front of
#: the robot (sim).
SPOT_WAIT_S = 30.0
#: A sim detection farther than this from that spot is someone else, metres.
SPOT_RADIUS = 0.6
#: Nodding period of the head between the face and the legs, seconds (sim).
NOD_PERIOD = 2.0
#: The target turns this far (rad) to either side while posing, so several views are learned.
SWAY = 0.25
#: On a robot (hsr): the heights the head nods between, metres (an adult's face and hips).
FACE_HEIGHT = 1.55
BODY_HEIGHT = 0.8


@dataclass
class Learned:
    """What was seen: one appearance per frame used, a face crop, and what was skipped."""

    appearances: list[Appearance]
    face_crop: np.ndarray | None = None
    frames_seen: int = 0
    others: int = 0
    whole_images: bool = False
    """No people detector (OpenCV 5 has no HOG): every image was taken as one person's crop."""


# -- the simulator ---------------------------------------------------------------------------------


def stand_in_front(
    robot: SimRobot,
    distance: float = STAND_DISTANCE,
    source: str = "mission",
    wait_s: float = SPOT_WAIT_S,
) -> tuple[float, float, float]:
    """Hold the scenario's target ``distance`` metres from the robot, facing it, on the first free
    spot with a clear line of sight, searching from straight ahead outwards; return the spot
    ``(x, y, bearing)`` with the bearing relative to the robot's heading.

    Where other people stand on every such spot (the simulator may start one of them where the
    target starts), the simulation runs on, the robot standing still and the target waiting
    where she is, for up to ``wait_s`` seconds until one of them walks off a spot, as a
    bystander in front of a real robot would be asked to. UserError when the scenario has no
    target, or no spot is free (walls everywhere, or people on the free spots all that while).
    """
    target = next((w for w in robot.people if w.is_target), None)
    if target is None:
        raise UserError(f"{source}: scenario.target: the mission names no target to learn")
    from pfctl.backends.pybullet.walkers import PERSON_RADIUS

    planner = robot.planner.with_radius(PERSON_RADIUS)
    pose = robot.pose  # the robot stands still while she waits: the spots stay the same
    spots = _spots_in_front(pose, planner, distance)
    if not spots:
        raise UserError(f"{source}: no free spot {distance:g} m around the robot's start")
    others = [w for w in robot.people if w is not target]
    start = robot.time
    while True:
        for spot, bearing in spots:
            if all(math.hypot(w.x - spot.x, w.y - spot.y) >= 2 * PERSON_RADIUS for w in others):
                target.hold(spot.x, spot.y, math.atan2(pose.y - spot.y, pose.x - spot.x))
                return spot.x, spot.y, bearing
        waited = robot.time - start
        if waited >= wait_s:
            raise UserError(
                f"{source}: no free spot {distance:g} m around the robot's start: other people "
                f"stood on the free ones for {waited:.0f} s"
            )
        target.hold(target.x, target.y, target.theta)
        robot.step()


def _spots_in_front(
    pose: Pose2D, planner: GridPlanner, distance: float
) -> list[tuple[Pose2D, float]]:
    """The spots ``distance`` m from ``pose`` free of walls and furniture with a clear line of
    sight to it, each with its bearing from the heading, straight ahead first, then outwards
    by 0.25 rad to either side."""
    spots = []
    for k in range(25):
        bearing = (k + 1) // 2 * (0.25 if k % 2 else -0.25)
        if abs(bearing) > math.pi:
            break
        spot = pose.compose(Pose2D(distance * math.cos(bearing), distance * math.sin(bearing)))
        xy = np.array([spot.x, spot.y])
        if not planner.is_free(xy):
            continue
        line = np.linspace([pose.x, pose.y], xy, 20)
        if np.min(planner.clearance_at(line)) <= 0.05:
            continue
        spots.append((spot, bearing))
    return spots


def learn_in_sim(
    mission: Mission,
    seconds: float,
    seed: int | None,
    params: IdentityParams,
    progress: Progress,
    source: str = "mission",
) -> Learned:
    """Frames of the target posing in front of the simulated robot (see the module docstring)."""
    from pfctl.app.sim import sim_config
    from pfctl.backends.pybullet.simulation import SimRobot
    from pfctl.core.perception.vision import MaskPersonDetector

    learned = Learned([])
    encoder = FaceEncoder(params.face)
    cam = mission.sensors.camera
    with SimRobot(sim_config(mission, seed)) as robot:
        x, y, bearing = stand_in_front(robot, source=source)
        target = next(w for w in robot.people if w.is_target)
        facing = target.theta
        detector = MaskPersonDetector(
            robot.person_instances(),
            robot.people_bodies.parts(),
            min_pixels=mission.perception.vision.min_pixels,
        )
        eye = cam.mount_height
        face_h = target.height - 0.11
        body_h = 0.45 * target.height
        dt = 1.0 / mission.behavior.tick_hz
        steps = max(1, math.ceil(seconds / dt))
        task = progress.add_task("learning", total=steps)
        for i in range(steps):
            t = i * dt
            look = face_h if (t % NOD_PERIOD) < NOD_PERIOD / 2 else body_h
            tilt = math.atan2(look - eye, STAND_DISTANCE)
            robot.point_head(HeadTarget(bearing, tilt))
            target.hold(x, y, facing + SWAY * math.sin(2 * math.pi * t / 3.0))
            robot.step()
            progress.update(task, advance=1)
            frame = robot.observe().rgbd
            if frame is None:
                continue
            _learn_frame(learned, frame, detector, (x, y), params, encoder)
    return learned


def learn_on_robot(
    robot: Robot,
    detector: PersonDetector,
    seconds: float,
    tick_hz: float,
    params: IdentityParams,
    progress: Progress,
    now: Callable[[], float],
    camera_height: float,
) -> Learned:
    """Frames of the person standing :data:`STAND_DISTANCE` m in front of a real robot (or the
    simulated house served over ROS), for ``seconds`` of the robot's clock ``now()``: the base
    stands still, the head looks straight ahead and nods between a face at
    :data:`FACE_HEIGHT` and a body at :data:`BODY_HEIGHT`; the person is the detection nearest
    the spot in front of the robot (within :data:`SPOT_RADIUS`). The frames are kept and learned
    from once the robot has been told to stand still for good: a face embedding, holding the
    interpreter, must not starve the robot's message threads while its watchdog runs."""
    learned = Learned([])
    frames: list[RgbdFrame] = []
    start = now()
    first = robot.observe()
    spot = first.pose.compose(Pose2D(STAND_DISTANCE, 0.0))
    task = progress.add_task("learning", total=max(1, math.ceil(seconds * tick_hz)))
    while now() - start < seconds:
        t = now() - start
        look = FACE_HEIGHT if (t % NOD_PERIOD) < NOD_PERIOD / 2 else BODY_HEIGHT
        robot.command(STOP, HeadTarget(0.0, math.atan2(look - camera_height, STAND_DISTANCE)))
        robot.step()
        progress.update(task, advance=1)
        frame = robot.observe().rgbd
        if frame is not None:
            frames.append(frame)
    robot.command(STOP)
    encoder = FaceEncoder(params.face)
    for frame in frames:
        _learn_frame(learned, frame, detector, (spot.x, spot.y), params, encoder)
    return learned


def learn_on_hsr(
    mission: Mission, seconds: float, params: IdentityParams, progress: Progress
) -> Learned:
    """:func:`learn_on_robot` on the HSR over ROS 1 (``backend.hsr``); a robot lost meanwhile
    raises :class:`~pfctl.core.robot.RobotLostError` (its base stopped)."""
    from pfctl.app.hsr import hsr_config
    from pfctl.backends.hsr.robot import HsrRobot

    with HsrRobot(hsr_config(mission), node_name="pfctl_learn_target") as robot:
        detector = robot.person_detector()
        if detector is None:
            raise UserError(
                "backend.hsr.person_labels: is null (and person_keypoints too), so the robot "
                "detects no one to learn"
            )
        return learn_on_robot(
            robot,
            detector,
            seconds,
            mission.behavior.tick_hz,
            params,
            progress,
            now=lambda: robot.time,
            camera_height=mission.sensors.camera.mount_height,
        )


def _learn_frame(
    learned: Learned,
    frame: RgbdFrame,
    detector: PersonDetector,
    spot: tuple[float, float],
    params: IdentityParams,
    encoder: FaceEncoder,
) -> None:
    """Learn from the person of ``frame`` nearest ``spot`` (others are counted)."""
    learned.frames_seen += 1
    detections = detector.detect(frame)
    x, y = spot
    near = [d for d in detections if math.hypot(d.position[0] - x, d.position[1] - y) < SPOT_RADIUS]
    learned.others += len(detections) - len(near)
    if not near:
        return
    det = min(near, key=lambda d: math.hypot(d.position[0] - x, d.position[1] - y))
    _add(learned, frame.rgb, det, params, encoder)


def _add(
    learned: Learned,
    rgb: np.ndarray,
    det: PersonDetection,
    params: IdentityParams,
    encoder: FaceEncoder,
) -> None:
    a = describe(rgb, det, params, encoder)
    if a.upper is None and a.lower is None and a.face is None:
        return
    learned.appearances.append(a)
    if a.face_box is not None and learned.face_crop is None:
        x0, y0, x1, y1 = a.face_box
        crop = rgb[max(0, y0) : y1, max(0, x0) : x1]
        if crop.size:
            learned.face_crop = crop.copy()


# -- images and videos -----------------------------------------------------------------------------


def _images(path: Path) -> Iterator[tuple[str, np.ndarray]]:
    """``(name, rgb)`` of each image of a folder, an image file or a video's frames."""
    import cv2

    if path.is_dir():
        files = sorted(f for f in path.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise UserError(f"--from {path}: no images ({', '.join(IMAGE_SUFFIXES)}) in the folder")
    elif path.is_file():
        files = [path] if path.suffix.lower() in IMAGE_SUFFIXES else []
    else:
        raise UserError(f"--from {path}: no such file or folder")
    if files:
        for f in files:
            bgr = cv2.imread(str(f), cv2.IMREAD_COLOR)
            if bgr is None:
                raise UserError(f"--from {f}: not an image OpenCV can read")
            yield f.name, cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
        return
    video = cv2.VideoCapture(str(path))
    try:
        if not video.isOpened():
            raise UserError(f"--from {path}: neither an image nor a video OpenCV can read")
        total = int(video.get(cv2.CAP_PROP_FRAME_COUNT))
        wanted = set(
            np.linspace(0, max(total - 1, 0), min(MAX_VIDEO_FRAMES, max(total, 1)))
            .round()
            .astype(int)
        )
        index, read = 0, 0
        while True:
            ok, bgr = video.read()
            if not ok:
                break
            if total <= 0 or index in wanted:
                yield f"{path.name}#{index}", cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
                read += 1
                if total <= 0 and read >= MAX_VIDEO_FRAMES:
                    break
            index += 1
        if read == 0:
            raise UserError(f"--from {path}: no frame could be read")
    finally:
        video.release()


PeopleFinder = Callable[[np.ndarray], list[tuple[tuple[int, int, int, int], float]]]
"""Finds people in an RGB image: ``[(box, score), ...]``."""


def hog_finder() -> PeopleFinder | None:
    """OpenCV's HOG people detector as a :data:`PeopleFinder` (upscaling small images), or None
    when the installed OpenCV has none."""
    if not hog_available():
        return None
    hog = HogPersonDetector()

    def find(rgb: np.ndarray) -> list[tuple[tuple[int, int, int, int], float]]:
        hog.upscale = 2.0 if rgb.shape[0] < 400 else 1.0
        return hog.boxes(rgb)

    return find


def learn_from_images(
    path: Path,
    pick: int | None,
    params: IdentityParams,
    progress: Progress,
    finder: PeopleFinder | None = None,
) -> Learned:
    """Appearances of the person in the images/video at ``path`` (see the module docstring);
    ``finder`` finds the people in an image (default: :func:`hog_finder`)."""
    learned = Learned([])
    hog = finder if finder is not None else hog_finder()
    learned.whole_images = hog is None
    encoder = FaceEncoder(params.face)
    crowded: list[str] = []
    task = progress.add_task("learning", total=None)
    for name, rgb in _images(path):
        learned.frames_seen += 1
        progress.update(task, advance=1)
        h, w = rgb.shape[:2]
        boxes: list[tuple[tuple[int, int, int, int], float]] = []
        if hog is not None:
            boxes = sorted(hog(rgb), key=lambda bs: bs[0][0] + bs[0][2])
        if not boxes:
            if hog is not None and h < 1.5 * w:
                continue
            boxes = [((0, 0, w, h), 0.0)]
        if len(boxes) > 1:
            if pick is None:
                crowded.append(f"{name}: {len(boxes)}")
                continue
            if pick > len(boxes):
                raise UserError(f"--pick {pick}: {name} shows only {len(boxes)} people")
            learned.others += len(boxes) - 1
            boxes = [boxes[pick - 1]]
        box, score = boxes[0]
        det = PersonDetection(box, (math.nan, math.nan, math.nan), score)
        _add(learned, rgb, det, params, encoder)
    if crowded:
        shown = "; ".join(crowded[:5]) + ("; ..." if len(crowded) > 5 else "")
        raise UserError(
            f"--from {path}: several people in {len(crowded)} image(s) ({shown}); "
            "choose one with --pick N (1 = leftmost)"
        )
    return learned


__all__ = [
    "MAX_VIDEO_FRAMES",
    "SPOT_WAIT_S",
    "STAND_DISTANCE",
    "SWAY",
    "Learned",
    "PeopleFinder",
    "hog_finder",
    "learn_from_images",
    "learn_in_sim",
    "learn_on_hsr",
    "learn_on_robot",
    "stand_in_front",
]
