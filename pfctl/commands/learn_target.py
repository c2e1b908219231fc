"""`pfctl learn-target MISSION --out target.npz`: learn what the target looks like (§II-E).

The profile (:class:`pfctl.core.perception.identity.profile.TargetProfile`) holds the target's
upper- and lower-body clothing histograms in the mission's ``perception.identity`` colour space and
bins, and the 128-D embeddings of their face. Two sources:

- ``--backend sim`` (the default): the scenario's target stands ~1.4 m in front of the simulated
  robot, facing it and turning a little from side to side; the robot turns its head to them and
  nods between their face and their legs, so it sees both, for ``--seconds`` simulated seconds.
  Frames from the simulated camera go through the mask person detector (the simulator's
  stand-in for OpenPose); the person is the detection nearest the spot they were asked to
  stand on, as a person on a real robot would be asked to stand in front of it.
- ``--backend hsr``: the same on a Toyota HSR over ROS 1 (or the simulated house served by
  ``pfctl sim serve-hsr --pose-target``): the person stands :data:`STAND_DISTANCE` m straight in
  front of the robot, which stands still and nods its head between a face and a body height for
  ``--seconds`` of ROS time; detections come from the mission's ``backend.hsr.person_labels``
  (or ``person_keypoints``).
- ``--from PATH``: a folder of images (``.png``, ``.jpg``, ...), one image, or a video file (at
  most :data:`MAX_VIDEO_FRAMES` frames, evenly spaced) of the person, read with OpenCV. Each
  image is searched with OpenCV's HOG people detector. When it finds nobody and the image is
  portrait (height ≥ 1.5 × width), the image is taken as a crop of one person; otherwise the
  image is skipped (OpenCV 5.0 has no HOG detector: then every image is taken whole as a crop
  of one person). Where it finds several people, ``--pick N`` takes the N-th from the left
  (1 = leftmost); without ``--pick`` that is an error listing what was seen.

Fails with one line (exit 2) and writes nothing when it saw no person, or several and no
``--pick``. Writes the profile (and ``--plot``'s PNG of the histograms and a face crop)
atomically.
"""

from __future__ import annotations

import io
import math
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn

from pfctl.app.perception import identity_params
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.faces import FaceEncoder
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import (
    Appearance,
    TargetProfile,
    describe,
    learn_profile,
)
from pfctl.core.perception.vision import (
    HogPersonDetector,
    PersonDetection,
    PersonDetector,
    hog_available,
)
from pfctl.core.robot import STOP, HeadTarget, Pose2D, RgbdFrame, Robot, RobotLostError
from pfctl.errors import UserError
from pfctl.files import atomic_write_all
from pfctl.mission import Mission, load_mission

if TYPE_CHECKING:
    from pfctl.backends.pybullet.simulation import SimRobot

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".ppm", ".pgm")
#: Frames read from a video at most (evenly spaced over it).
MAX_VIDEO_FRAMES = 60
#: Where the target is asked to stand, metres in front of the robot (sim).
STAND_DISTANCE = 1.4
#: A sim detection farther than this from that spot is someone else, metres.
SPOT_RADIUS = 0.6
#: Nodding period of the head between the face and the legs, seconds (sim).
NOD_PERIOD = 2.0
#: The target turns this far (rad) to either side while posing, so several views are learned.
SWAY = 0.25
#: On a robot (hsr): the heights the head nods between, metres (an adult's face and hips).
FACE_HEIGHT = 1.55
BODY_HEIGHT = 0.8

BACKENDS = ("sim", "hsr")


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
    robot: SimRobot, distance: float = STAND_DISTANCE, source: str = "mission"
) -> tuple[float, float, float]:
    """Hold the scenario's target ``distance`` metres from the robot, facing it, on the first free
    spot with a clear line of sight, searching from straight ahead outwards; return the spot
    ``(x, y, bearing)`` with the bearing relative to the robot's heading. UserError when the
    scenario has no target or no spot is free."""
    target = next((w for w in robot.people if w.is_target), None)
    if target is None:
        raise UserError(f"{source}: scenario.target: the mission names no target to learn")
    from pfctl.backends.pybullet.walkers import PERSON_RADIUS

    planner = robot.planner.with_radius(PERSON_RADIUS)
    pose = robot.pose
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
        others = [w for w in robot.people if w is not target]
        if any(math.hypot(w.x - spot.x, w.y - spot.y) < 2 * PERSON_RADIUS for w in others):
            continue
        target.hold(spot.x, spot.y, math.atan2(pose.y - spot.y, pose.x - spot.x))
        return spot.x, spot.y, bearing
    raise UserError(f"{source}: no free spot {distance:g} m around the robot's start")


def learn_in_sim(
    mission: Mission,
    seconds: float,
    seed: int | None,
    params: IdentityParams,
    progress: Progress,
    source: str = "mission",
) -> Learned:
    """Frames of the target posing in front of the simulated robot (see the module docstring)."""
    from pfctl.backends.pybullet.simulation import SimOptions, SimRobot
    from pfctl.core.perception.vision import MaskPersonDetector

    learned = Learned([])
    encoder = FaceEncoder(params.face)
    cam = mission.sensors.camera
    with SimRobot(mission, SimOptions(seed=seed)) as robot:
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
    from once the robot has been told to stand still for good: a face embedding (~0.1 s, holding
    the interpreter) must not starve the robot's message threads while its watchdog runs."""
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


def _learn_on_hsr(
    mission: Mission, seconds: float, params: IdentityParams, progress: Progress
) -> Learned:
    """:func:`learn_on_robot` on the HSR over ROS 1 (``backend.hsr``)."""
    from pfctl.backends.hsr.robot import HsrRobot

    with HsrRobot(mission, node_name="pfctl_learn_target") as robot:
        detector = robot.person_detector()
        if detector is None:
            raise UserError(
                "backend.hsr.person_labels: is null (and person_keypoints too), so the robot "
                "detects no one to learn"
            )
        try:
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
        except RobotLostError as err:
            sys.stderr.write(f"pfctl: error: {err}; the base was stopped, nothing written\n")
            raise typer.Exit(1) from None


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


# -- the command -----------------------------------------------------------------------------------


def learn_target(
    mission: Annotated[Path, typer.Argument(help="A mission YAML.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="The target profile to write (.npz).")],
    backend: Annotated[
        str | None,
        typer.Option(
            "--backend", help="Learn on a robot: sim (default unless --from) or hsr (ROS 1)."
        ),
    ] = None,
    source: Annotated[
        Path | None,
        typer.Option("--from", help="Learn from a folder of images, an image or a video file."),
    ] = None,
    pick: Annotated[
        int | None,
        typer.Option("--pick", help="With --from: the N-th person from the left (1 = leftmost)."),
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", help="Also write a PNG of the histograms and face.")
    ] = None,
    seconds: Annotated[
        float, typer.Option("--seconds", help="With --backend: seconds (sim or ROS time) to look.")
    ] = 6.0,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed",
            help="Sim seed (default: scenario.seed); people's faces depend on it, so use the "
            "seed you will follow with.",
        ),
    ] = None,
) -> None:
    """Learn the target's clothes and face and write a target profile (.npz)."""
    if source is not None and backend is not None:
        raise UserError("--from and --backend: choose one source of pictures")
    if backend is not None and backend not in BACKENDS:
        raise UserError(f"--backend {backend}: expected one of {', '.join(BACKENDS)}")
    if pick is not None and (source is None or pick < 1):
        raise UserError(f"--pick {pick}: expected a positive number, with --from")
    if not (math.isfinite(seconds) and seconds > 0):
        raise UserError(f"--seconds: expected a positive duration, got {seconds}")
    if out.suffix.lower() != ".npz":
        raise UserError(f"--out {out}: expected a path ending in .npz")
    if out.is_dir():
        raise UserError(f"--out {out}: is a directory, expected a file path")
    if plot is not None and plot.suffix.lower() != ".png":
        raise UserError(f"--plot {plot}: expected a path ending in .png")
    loaded = load_mission(mission)
    params = identity_params(loaded)
    console = Console(stderr=True)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.0f} frames"),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        if source is not None:
            learned = learn_from_images(source, pick, params, progress)
            where = f"--from {source}"
        elif backend == "hsr":
            learned = _learn_on_hsr(loaded, seconds, params, progress)
            where = f"--backend hsr: the person {STAND_DISTANCE:g} m in front of the robot"
        else:
            learned = learn_in_sim(loaded, seconds, seed, params, progress, str(mission))
            where = f"{mission}: the simulated target"
    if not learned.appearances:
        raise UserError(
            f"{where}: saw no person in {learned.frames_seen} frame(s); nothing written"
        )
    try:
        profile = learn_profile(learned.appearances, params)
    except ValueError:
        raise UserError(
            f"{where}: never saw both the upper and the lower body; nothing written"
        ) from None
    files: list[tuple[Path, bytes]] = [(out, profile.to_bytes())]
    if plot is not None:
        files.append((plot, profile_png(profile, learned.face_crop)))
    for path, _ in files:
        if not path.parent.is_dir():
            raise UserError(f"{path}: its folder does not exist")
    try:
        atomic_write_all(files)
    except OSError as err:
        raise UserError(f"{out}: cannot write: {err.strerror or err}") from None
    _report(profile, learned, out, plot)


def dominant_colours(
    hist: np.ndarray, params: ClothesParams, n: int = 3
) -> list[tuple[str, float]]:
    """The ``n`` heaviest bins of a histogram as ``(#rrggbb of the bin centre, share)``."""
    out = []
    for index in np.argsort(-hist)[:n]:
        if hist[index] <= 0:
            break
        out.append((bin_hex(int(index), params), float(hist[index])))
    return out


def bin_hex(index: int, params: ClothesParams) -> str:
    """The colour of a histogram bin's centre as ``#rrggbb``."""
    import cv2

    b = params.bins
    ijk = np.unravel_index(index, b)
    top = (180, 256, 256) if params.color_space == "hsv" else (256, 256, 256)
    centre = np.array([[[(ijk[c] + 0.5) * top[c] / b[c] for c in range(3)]]], dtype=np.float32)
    pix = np.clip(centre, 0, 255).astype(np.uint8)
    if params.color_space == "hsv":
        pix = cv2.cvtColor(pix, cv2.COLOR_HSV2RGB)
    elif params.color_space == "lab":
        pix = cv2.cvtColor(pix, cv2.COLOR_LAB2RGB)
    r, g, bb = (int(v) for v in pix[0, 0])
    return f"#{r:02x}{g:02x}{bb:02x}"


def profile_png(profile: TargetProfile, face: np.ndarray | None) -> bytes:
    """A PNG: the upper and lower histograms as bars in their bins' colours, and a face crop."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    params = profile.clothes
    fig = Figure(figsize=(10, 4.2))
    grid = fig.add_gridspec(2, 4)
    colours = [bin_hex(i, params) for i in range(params.size)]
    for row, (label, hist) in enumerate(
        (("upper body", profile.upper), ("lower body", profile.lower))
    ):
        ax = fig.add_subplot(grid[row, :3])
        ax.bar(np.arange(params.size), hist, color=colours, width=1.0, edgecolor="none")
        ax.set_ylabel(f"{label}\nshare")
        ax.set_xlim(-0.5, params.size - 0.5)
    ax = fig.add_subplot(grid[:, 3])
    ax.axis("off")
    if face is not None:
        ax.imshow(face)
        ax.set_title(f"a face ({len(profile.faces)} samples)")
    else:
        ax.set_title("no face seen")
    fig.suptitle(
        f"target profile: {profile.frames} frames, {profile.color_space} {list(profile.bins)} bins"
    )
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return buf.getvalue()


def _report(profile: TargetProfile, learned: Learned, out: Path, plot: Path | None) -> None:
    console = Console(width=100, soft_wrap=True)
    params = profile.clothes
    console.print(
        f"learned from {len(learned.appearances)} of {learned.frames_seen} frames: "
        f"{len(profile.faces)} face samples, histograms in {params.color_space} "
        f"{list(params.bins)}"
    )
    for label, hist in (("upper", profile.upper), ("lower", profile.lower)):
        tops = ", ".join(f"{c} {share:.0%}" for c, share in dominant_colours(hist, params))
        console.print(f"  {label} body: {tops}")
    if learned.whole_images:
        console.print("  OpenCV has no HOG people detector: each image was taken as one person")
    if learned.others:
        console.print(f"  ignored {learned.others} detections of other people")
    if len(profile.faces) == 0:
        console.print("  no face seen: this profile identifies by clothes only")
    console.print(f"wrote {out}" + (f" and {plot}" if plot is not None else ""))


__all__ = ["learn_from_images", "learn_in_sim", "learn_target", "stand_in_front"]
