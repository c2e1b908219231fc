"""`pfctl learn-target MISSION --out target.npz`: learn what the target looks like (§II-E).

The profile (:class:`pfctl.core.perception.identity.profile.TargetProfile`) holds the target's
upper- and lower-body clothing histograms in the mission's ``perception.identity`` colour space and
bins, and the 128-D embeddings of their face. Three sources (:mod:`pfctl.app.learn_target` says
how each one sees the person): ``--backend sim`` (the default), the scenario's target posing in
front of the simulated robot; ``--backend hsr``, a person standing in front of a Toyota HSR over
ROS 1 (or of the simulated house served by ``pfctl sim serve-hsr --pose-target``); ``--from PATH``,
a folder of images, one image or a video file, with ``--pick N`` choosing among several people.

Fails with one line (exit 2) and writes nothing when it saw no person, or several and no
``--pick``. Writes the profile (and ``--plot``'s PNG of the histograms and a face crop)
atomically.
"""

from __future__ import annotations

import io
import math
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn

from pfctl.app.learn_target import (
    STAND_DISTANCE,
    Learned,
    learn_from_images,
    learn_in_sim,
    learn_on_hsr,
)
from pfctl.app.perception import identity_params
from pfctl.commands import check_seed
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.identity.profile import TargetProfile, learn_profile
from pfctl.core.robot import RobotLostError
from pfctl.errors import UserError
from pfctl.files import atomic_write_all, check_output_file
from pfctl.mission import load_mission

BACKENDS = ("sim", "hsr")


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
            callback=check_seed,
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
    if plot is not None and plot.suffix.lower() != ".png":
        raise UserError(f"--plot {plot}: expected a path ending in .png")
    check_output_file(out, "--out", make_folder=False)
    check_output_file(plot, "--plot", make_folder=False)
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
            try:
                learned = learn_on_hsr(loaded, seconds, params, progress)
            except RobotLostError as err:
                sys.stderr.write(f"pfctl: error: {err}; the base was stopped, nothing written\n")
                raise typer.Exit(1) from None
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


__all__ = ["bin_hex", "dominant_colours", "learn_target", "profile_png"]
