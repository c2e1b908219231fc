"""``pfctl track``: how well the people tracker does on recorded data.

- ``pfctl track evaluate BAG --ground-truth TOPIC [--scan-topic T] [--frame F] [--radius 0.75]
  [--mission M] [--out DIR]``: the perception ``pfctl replay`` runs, on every scan of the bag,
  scored by CLEAR-MOT (MOTA, MOTP, misses, false positives, ID switches) at the scans annotated
  on ``TOPIC`` (``leg_tracker/Person``, in the laser's frame) — :mod:`pfctl.app.track_evaluation`.
  Prints the figures; writes ``metrics.json`` and ``tracks.png`` (x and y of the tracks and the
  annotated people against time, with the misses, false positives and switches marked) together,
  so an error or Ctrl-C leaves nothing half-written. ``--decimate N`` keeps every N-th scan and
  ``--spread K`` repeats each kept scan K times with its stamps spread to the next one: the same
  bag at other rates. ``--min-bearing A --max-bearing B`` (degrees, laser frame) score only the
  annotations and tracks within that wedge, where the annotator marked people (the benchmark's
  own script scores ``general_tracking_moving`` within −80° to 12°).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pfctl.app.track_evaluation import TrackEvaluation, evaluate_tracks, evaluation_mission
from pfctl.errors import UserError
from pfctl.files import atomic_write_all, check_output_dir
from pfctl.plots.tracking import tracking_figure
from pfctl.progress import progress_bar

app = typer.Typer(
    help="People tracking on recorded data: `pfctl track evaluate`.", no_args_is_help=True
)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _metrics(
    bag: Path,
    ground_truth: str,
    radius: float,
    bearings: tuple[float, float] | None,
    ev: TrackEvaluation,
) -> dict[str, object]:
    r = ev.result
    return {
        "bag": str(bag),
        "ground_truth_topic": ground_truth,
        "scan_topic": ev.scan_topic,
        "frame": ev.frame,
        "radius": radius,
        "bearings_deg": None if bearings is None else list(bearings),
        **{k: _finite(v) if isinstance(v, float) else v for k, v in r.as_dict().items()},
        "scans": len(ev.tracks),
        "unpaired_annotated_scans": ev.unpaired,
        "track_ids_reported": len({i for s in ev.tracks for i in s.ids}),
    }


@app.command("evaluate")
def evaluate(
    bag: Annotated[Path, typer.Argument(help="A ROS 1 .bag file or a ROS 2 bag folder.")],
    ground_truth: Annotated[
        str,
        typer.Option("--ground-truth", help="Topic of the annotated people (leg_tracker/Person)."),
    ],
    scan_topic: Annotated[
        str | None,
        typer.Option("--scan-topic", help="LaserScan topic (default: the bag's only one)."),
    ] = None,
    frame: Annotated[
        str | None,
        typer.Option(
            "--frame", help="Fixed frame of tracking (default: map, else odom, else the laser's)."
        ),
    ] = None,
    radius: Annotated[
        float, typer.Option("--radius", help="Largest distance of a match, m.")
    ] = 0.75,
    mission_path: Annotated[
        Path | None,
        typer.Option("--mission", help="Take the perception parameters from this mission."),
    ] = None,
    out: Annotated[
        Path, typer.Option("--out", help="Folder for metrics.json and tracks.png.")
    ] = Path("track-evaluation"),
    decimate: Annotated[
        int, typer.Option("--decimate", min=1, help="Use every N-th scan only.")
    ] = 1,
    spread: Annotated[
        int,
        typer.Option(
            "--spread", min=1, help="Repeat each scan K times, stamps spread to the next one."
        ),
    ] = 1,
    min_bearing: Annotated[
        float,
        typer.Option(
            "--min-bearing", help="Score only people and tracks at bearings from this, degrees."
        ),
    ] = -180.0,
    max_bearing: Annotated[
        float,
        typer.Option(
            "--max-bearing", help="Score only people and tracks at bearings up to this, degrees."
        ),
    ] = 180.0,
) -> None:
    """Score the tracker on a bag with annotated people (CLEAR-MOT)."""
    if not (math.isfinite(radius) and radius > 0):
        raise UserError(f"--radius: expected a distance > 0 m, got {radius:g}")
    if not -180.0 <= min_bearing < max_bearing <= 180.0:
        raise UserError(
            f"--min-bearing/--max-bearing: expected −180 ≤ min < max ≤ 180 degrees, got "
            f"{min_bearing:g} and {max_bearing:g}"
        )
    wedge = None if (min_bearing, max_bearing) == (-180.0, 180.0) else (min_bearing, max_bearing)
    mission = evaluation_mission(mission_path)
    check_output_dir(out, "--out")
    console = Console(stderr=True)
    ev = evaluate_tracks(
        bag,
        ground_truth,
        mission,
        scan_topic=scan_topic,
        frame=frame,
        radius=radius,
        decimate=decimate,
        spread=spread,
        bearings=None if wedge is None else (math.radians(wedge[0]), math.radians(wedge[1])),
        progress=lambda total: progress_bar(console, "replaying", total),
    )
    r = ev.result
    metrics = _metrics(bag, ground_truth, radius, wedge, ev)
    png = tracking_figure(
        [(p.time, p.ids, p.xy) for p in ev.truth],
        [(s.stamp, s.ids, s.xy) for s in ev.tracks],
        ev.frames,
        r,
        bag.name,
        origin=ev.tracks[0].stamp,
    )
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_all(
        [(out / "metrics.json", json.dumps(metrics, indent=2) + "\n"), (out / "tracks.png", png)]
    )
    within = "" if wedge is None else f", bearings {wedge[0]:g}° to {wedge[1]:g}°"
    print(
        f"{bag.name}: MOTA {100 * r.mota:.1f} %, MOTP {r.motp:.3f} m, misses {r.misses}, "
        f"false positives {r.false_positives}, ID switches {r.id_switches}, "
        f"ground truth {r.ground_truth} at {r.frames} annotated scans "
        f"(radius {radius:g} m, frame {ev.frame!r}{within}) → {out / 'metrics.json'}, "
        f"{out / 'tracks.png'}"
    )
    if ev.unpaired:
        print(
            f"note: {ev.unpaired} annotated scans were not replayed (not posed, or thinned out): "
            "not scored",
            file=sys.stderr,
        )
    for reason, count in sorted(ev.skipped.items()):
        print(f"note: skipped {count} messages: {reason}", file=sys.stderr)


__all__ = ["app", "evaluate"]
