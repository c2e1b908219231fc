"""``pfctl replay BAG``: the perception run on a recorded bag → ``tracks.csv`` and ``tracks.png``.

Leg detection and tracking run on every scan of the bag (and, when the bag has RGB-D topics,
person detection — from the bag's person-label image when it has one (``/pfctl/person_labels``),
else from its person keypoints (``/pfctl/person_keypoints``, placed in 3-D by the depth), else
OpenCV's HOG — fuses into the same tracks; with ``--target`` Algorithm 2 names the target),
posed in a fixed frame through the bag's ``/tf``. After each scan, every confirmed track that is
currently seen (coasting tracks are left out: they are extrapolations) is one row of
``tracks.csv``: ``t,track_id,x,y,vx,vy,confidence,is_target``. ``tracks.png`` draws the tracks
over the bag's ``/map`` when it has one, else over the laser returns seen from where they were
recorded. Both files are written together at the end, so an error or Ctrl-C leaves nothing
half-written.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console

from pfctl.app.perception import build_perception
from pfctl.app.profiles import load_target_profile
from pfctl.app.tracks_file import tracks_csv
from pfctl.backends.hsr.person_labels import label_detector
from pfctl.bags.replay import Replay, open_replay
from pfctl.core.episode import TrackRow
from pfctl.core.perception.pipeline import Perception
from pfctl.core.perception.vision import (
    GivenPersonDetector,
    HogPersonDetector,
    PersonDetector,
    hog_available,
)
from pfctl.core.robot import LaserScan, RgbdFrame
from pfctl.errors import UserError
from pfctl.files import atomic_write_all, check_output_dir
from pfctl.mission import Mission, load_mission
from pfctl.progress import progress_bar

#: A track unseen for longer than this (s) is drawn with a gap.
GAP_S = 0.5
#: At most this many laser returns are drawn as the backdrop of tracks.png.
BACKDROP_POINTS = 60_000


def _mission(path: Path | None) -> Mission:
    """The mission whose perception parameters to use; without one, every default (the map is
    a placeholder: replay does not use it)."""
    if path is None:
        placeholder = {"name": "all", "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}
        return Mission.model_validate({"name": "replay", "map": {"regions": [placeholder]}})
    if not path.is_file():
        raise UserError(f"--mission {path}: no such mission file")
    return load_mission(path)


def replay(
    bag: Annotated[Path, typer.Argument(help="A ROS 1 .bag file or a ROS 2 bag folder.")],
    scan_topic: Annotated[
        str | None,
        typer.Option("--scan-topic", help="LaserScan topic (default: the bag's only one)."),
    ] = None,
    frame: Annotated[
        str | None,
        typer.Option(
            "--frame", help="Fixed frame of the tracks (default: map, else odom, else the laser's)."
        ),
    ] = None,
    target: Annotated[
        Path | None,
        typer.Option("--target", help="A target profile (pfctl learn-target) to identify."),
    ] = None,
    out: Annotated[
        Path, typer.Option("--out", help="Folder for tracks.csv and tracks.png.")
    ] = Path("replay"),
    mission_path: Annotated[
        Path | None,
        typer.Option("--mission", help="Take the perception parameters from this mission."),
    ] = None,
    camera: Annotated[
        bool, typer.Option("--camera/--no-camera", help="Use the bag's RGB-D topics if any.")
    ] = True,
) -> None:
    """Run leg detection, tracking (and vision + identification) on a recorded bag."""
    console = Console(stderr=True)
    mission = _mission(mission_path)
    profile = load_target_profile(target) if target is not None else None
    check_output_dir(out, "--out")
    source = open_replay(bag, scan_topic=scan_topic, frame=frame, camera=camera)
    with source.bag:
        if profile is not None and source.camera is None:
            raise UserError(
                f"{bag}: --target needs the bag's camera (RGB, depth and camera_info topics)"
            )
        detector: PersonDetector | None = None
        if source.camera is not None and source.camera.labels is not None:
            detector = label_detector(mission.perception.vision.min_pixels)
        elif source.camera is not None and source.camera.keypoints is not None:
            detector = GivenPersonDetector()
        elif source.camera is not None:
            if not hog_available():
                raise UserError("the camera needs OpenCV's HOG people detector (OpenCV < 5)")
            detector = HogPersonDetector()
        perception = build_perception(mission, detector=detector, profile=profile)
        rows, points, frames = _run(source, perception, console)
    csv_text = tracks_csv(rows)
    png = _plot(source, rows, points, bag.name)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_all([(out / "tracks.csv", csv_text), (out / "tracks.png", png)])
    ids = {r[1] for r in rows}
    target_rows = sum(1 for r in rows if r[7])
    print(
        f"{bag.name}: {len(ids)} tracks over {rows[-1][0] - rows[0][0] if rows else 0.0:.1f} s "
        f"in frame {source.frame!r} ({source.scan_topic}"
        + (f", {frames} camera frames" if source.camera else "")
        + (f", target in {target_rows} rows" if profile is not None else "")
        + f") → {out / 'tracks.csv'}, {out / 'tracks.png'}"
    )
    for reason, count in sorted(source.skipped.items()):
        print(f"note: skipped {count} messages: {reason}", file=sys.stderr)


def _run(
    source: Replay, perception: Perception, console: Console
) -> tuple[list[TrackRow], np.ndarray, int]:
    rows: list[TrackRow] = []
    backdrop: list[np.ndarray] = []
    frames = 0
    with progress_bar(console, "replaying", source.total()) as advance:
        for item in source.stream():
            advance(1)
            if isinstance(item, LaserScan):
                perception.on_scan(item)
                rows += perception.seen_track_rows(item.stamp)
                backdrop.append(item.points()[::4])
            elif isinstance(item, RgbdFrame):
                perception.on_frame(item)
                frames += 1
    points = np.vstack(backdrop) if backdrop else np.empty((0, 2))
    if len(points) > BACKDROP_POINTS:
        points = points[:: len(points) // BACKDROP_POINTS + 1]
    return rows, points, frames


def _plot(source: Replay, rows: list[TrackRow], points: np.ndarray, title: str) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 8))
    if source.grid is not None:
        g = source.grid
        shade = np.where(g < 0, 0.85, 1.0 - np.clip(g, 0, 100) / 100.0)
        h, w = g.shape
        x0, y0 = source.grid_origin
        r = source.grid_resolution
        ax.imshow(shade, cmap="gray", vmin=0, vmax=1, origin="lower",
                  extent=(x0, x0 + w * r, y0, y0 + h * r))  # fmt: skip
    elif len(points):
        ax.scatter(points[:, 0], points[:, 1], s=0.3, c="0.7", linewidths=0, label="laser returns")
    by_id: dict[int, list[TrackRow]] = {}
    for row in rows:
        by_id.setdefault(row[1], []).append(row)
    cmap = plt.get_cmap("tab20")
    for k, (tid, track) in enumerate(sorted(by_id.items())):
        xy = np.array([(r[2], r[3]) for r in track])
        t = np.array([r[0] for r in track])
        is_target = any(r[7] for r in track)
        color = "red" if is_target else cmap(k % 20)
        for piece in np.split(np.arange(len(t)), np.flatnonzero(np.diff(t) > GAP_S) + 1):
            ax.plot(xy[piece, 0], xy[piece, 1], "-", color=color, lw=2.2 if is_target else 1.2)
        ax.plot(xy[0, 0], xy[0, 1], "o", color=color, ms=4)
        ax.annotate(str(tid), xy[-1], fontsize=7, color=color)
    ax.plot([0], [0], "k^", ms=8, label=f"{source.frame} origin")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x in {source.frame} (m)")
    ax.set_ylabel(f"y in {source.frame} (m)")
    ax.set_title(f"{title}: {len(by_id)} tracks (start ●, id at the end; target red)")
    ax.legend(loc="upper right", fontsize=8)
    if len(rows):
        xy = np.array([(r[2], r[3]) for r in rows])
        lo, hi = xy.min(axis=0) - 1.0, xy.max(axis=0) + 1.0
        ax.set_xlim(min(lo[0], -0.5), max(hi[0], 0.5))
        ax.set_ylim(min(lo[1], -0.5), max(hi[1], 0.5))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


__all__ = ["replay"]
