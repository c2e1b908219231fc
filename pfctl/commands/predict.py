"""`pfctl predict`: where did the person go? Trajectory prediction (§II-E, §III-B).

- ``pfctl predict TRACK.csv --horizon 3``: predict a track (the subcommand name ``track`` may be
  left out), optionally clipped to a mission's map, with a PNG of every model's prediction.
- ``pfctl predict evaluate DATA``: ADE/FDE and time per call of every model on every
  observe/predict window of real tracks.
- ``pfctl predict search DATA...``: grid search of a model's hyperparameters, people split into
  train and test.
- ``pfctl predict experiment door``: the paper's door experiment on synthetic walks.

Every bad input is a :class:`pfctl.errors.UserError` (one line, exit 2); files are written
atomically. Tables and predictions go to stdout, progress and notes to stderr.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from enum import Enum
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from typer.core import TyperGroup

from pfctl.app.follower import prediction_params
from pfctl.app.trajectory_files import read_csv_trajectory, read_trajectories
from pfctl.commands import check_seed
from pfctl.core.follower import PredictionParams
from pfctl.core.mapping.grid import OccupancyGrid
from pfctl.core.mapping.house import HouseLayout
from pfctl.core.mapping.regions import RegionMap
from pfctl.core.mapping.walls import rasterize_house
from pfctl.core.prediction.clipping import ClippedPath, clip_prediction
from pfctl.core.prediction.door_experiment import CASES, run_door_experiment
from pfctl.core.prediction.evaluation import ModelSpec, Score, evaluate, make_windows
from pfctl.core.prediction.models import (
    DEFAULT_MODEL,
    MIN_POINTS,
    MODELS,
    PredictionError,
    make_model,
)
from pfctl.core.prediction.search import grid_search
from pfctl.core.prediction.trajectories import Trajectory
from pfctl.errors import UserError
from pfctl.files import check_output_file, write_output
from pfctl.mission import Mission, load_mission
from pfctl.mission.map_server import GridFileError, load_map_server
from pfctl.progress import progress_bar


class _PredictGroup(TyperGroup):
    """``pfctl predict TRACK ...`` runs the ``track`` subcommand: anything that is not the name
    of a subcommand (or ``--help``) is taken as the start of ``track``'s arguments."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        if args and args[0] not in self.commands and args[0] not in ("--help", "-h"):
            args = ["track", *args]
        return super().parse_args(ctx, args)


app = typer.Typer(
    cls=_PredictGroup,
    help=(
        "Predict where a person went: `pfctl predict TRACK.csv --horizon 3`, "
        "`pfctl predict evaluate DATA`, `pfctl predict search DATA`, "
        "`pfctl predict experiment door`."
    ),
    no_args_is_help=True,
)
experiment_app = typer.Typer(help="Experiments of the paper, synthetic.", no_args_is_help=True)
app.add_typer(experiment_app, name="experiment")

MODEL_NAMES = tuple(MODELS)

#: Most points ``pfctl predict TRACK`` predicts (horizon / step), refused before any array is
#: made: far beyond any real use (3 s at 0.4 s is 8 points), still well within memory with the
#: figure and the map (``--horizon 1e9 --step 0.001`` asked for TiB).
MAX_PREDICTED_POINTS = 1_000_000


class OutFormat(str, Enum):
    csv = "csv"
    json = "json"


class InFormat(str, Enum):
    csv = "csv"
    frames = "frames"


class Metric(str, Enum):
    ade = "ade"
    fde = "fde"
    both = "both"


# --------------------------------------------------------------------------------------------
# helpers


def _out() -> Console:
    return Console(width=100, soft_wrap=True)


def _err() -> Console:
    return Console(stderr=True, width=100, soft_wrap=True)


def _check_model(name: str, option: str = "--model") -> str:
    if name not in MODELS:
        raise UserError(f"{option} {name}: unknown model; expected one of {', '.join(MODELS)}")
    return name


def _model_list(values: Sequence[str] | None) -> list[str]:
    """``--models svr,cv --models poly3`` → ['svr', 'cv', 'poly3'] (default: every model)."""
    if not values:
        return list(MODEL_NAMES)
    names: list[str] = []
    for value in values:
        for part in value.split(","):
            name = _check_model(part.strip(), "--models")
            if name not in names:
                names.append(name)
    return names


def _positive(value: float | None, option: str, unit: str = "s") -> None:
    if value is not None and not (math.isfinite(value) and value > 0):
        raise UserError(f"{option}: expected a positive number of {unit}, got {value:g}")


def _predicted_points(horizon: float, step: float, track_step: bool) -> int:
    """How many points ``horizon`` seconds ``step`` apart are (at least one), refused over
    :data:`MAX_PREDICTED_POINTS` before any array is made (``track_step``: the step is the
    track's, not ``--step``)."""
    points = horizon / step
    if not points <= MAX_PREDICTED_POINTS:
        at = f"the track's step of {step:g} s" if track_step else f"--step {step:g}"
        raise UserError(
            f"--horizon {horizon:g}: {points:.3g} predicted points at {at}, over the limit of "
            f"{MAX_PREDICTED_POINTS:,}; use a shorter --horizon or a longer --step"
        )
    return max(1, math.ceil(points - 1e-9))


def _mission_params(mission: Mission | None, name: str) -> dict[str, Any]:
    """The mission's prediction settings as hyperparameters of model ``name``.

    A mission's ``prediction`` section describes *its* predictor (``prediction.model``): its SVR
    C/ε/γ and weighting are given to that model only (each model takes the parameters it has);
    every other model keeps its own defaults.
    """
    if mission is None or mission.prediction.model != name:
        return {}
    return dict(prediction_params(mission).params)


def _prepare_output(path: Path | None, option: str) -> None:
    if path is None:
        return
    check_output_file(path, option)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise UserError(f"{option} {path}: cannot create its folder: {err.strerror}") from None


def _load_tracks(
    data: Path, fmt: InFormat, fps: float | None, frame_step: float | None
) -> list[Trajectory]:
    if fmt is InFormat.frames and fps is None:
        raise UserError("--fps: required with --format frames (annotated steps per second)")
    if fmt is InFormat.csv and (fps is not None or frame_step is not None):
        raise UserError("--fps/--frame-step: only for --format frames; CSV times are seconds")
    _positive(fps, "--fps", "steps per second")
    _positive(frame_step, "--frame-step", "frame ids")
    return read_trajectories(data, fmt.value, fps=fps, frame_step=frame_step)


def _json_text(data: Any) -> str:
    return json.dumps(data, indent=2, allow_nan=False) + "\n"


# --------------------------------------------------------------------------------------------
# pfctl predict TRACK


def _map_of(mission: Mission) -> tuple[OccupancyGrid, HouseLayout, RegionMap]:
    layout = mission.layout()
    if mission.map.occupancy is not None:
        try:
            grid = load_map_server(mission.map.occupancy)
        except GridFileError as err:
            raise UserError(str(err)) from None
    else:
        grid = rasterize_house(
            layout, mission.map.resolution, wall_thickness=mission.map.wall_thickness
        )
    return grid, layout, RegionMap(layout)


def _fit_predict(
    name: str, history: Trajectory, times: np.ndarray, params: dict[str, Any], where: str
) -> np.ndarray:
    if len(history) < MIN_POINTS[name]:
        raise UserError(
            f"{where}: {len(history)} point(s) in the history, model {name} needs at least "
            f"{MIN_POINTS[name]} (use a longer --history or track)"
        )
    try:
        model = make_model(name, **params).fit(history.t, history.xy)
        return np.asarray(model.predict(times), dtype=float)
    except PredictionError as err:
        raise UserError(f"{where}: {name}: {err}") from None


def _track_csv(
    times: np.ndarray, xy: np.ndarray, clipped: ClippedPath | None, regions: RegionMap | None
) -> str:
    lines = ["t,x,y" + (",region,clipped" if clipped is not None else "")]
    for i, (t, (x, y)) in enumerate(zip(times, xy, strict=True)):
        row = f"{float(t)!r},{float(x)!r},{float(y)!r}"
        if clipped is not None and regions is not None:
            region = regions.locate((x, y)) or ""
            stopped = clipped.stop_index is not None and i >= clipped.stop_index
            row += f",{region},{int(stopped)}"
        lines.append(row)
    return "\n".join(lines) + "\n"


@app.command("track")
def track(
    track_file: Annotated[
        Path,
        typer.Argument(metavar="TRACK", help="CSV track with a header t,x,y.", show_default=False),
    ],
    horizon: Annotated[
        float | None,
        typer.Option("--horizon", help="Seconds ahead (default: the mission's, else 3)."),
    ] = None,
    model: Annotated[
        str | None,
        typer.Option(
            "--model", help=f"{' | '.join(MODEL_NAMES)} (default: mission's, else {DEFAULT_MODEL})."
        ),
    ] = None,
    mission_file: Annotated[
        Path | None,
        typer.Option(
            "--mission", help="Mission: its prediction settings, map (clipping) and regions."
        ),
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", help="PNG: history, every model's prediction, map.")
    ] = None,
    fmt: Annotated[OutFormat, typer.Option("--format", help="Output: csv or json.")] = (
        OutFormat.csv
    ),
    out: Annotated[
        Path | None, typer.Option("--out", help="Write the prediction here, not to stdout.")
    ] = None,
    step: Annotated[
        float | None,
        typer.Option("--step", help="Seconds between predicted points (default: the track's)."),
    ] = None,
    history_s: Annotated[
        float | None,
        typer.Option("--history", help="Seconds of track to fit (default: the mission's, else 3)."),
    ] = None,
) -> None:
    """Predict where the person of TRACK is HORIZON seconds after its last sample.

    Prints t,x,y of the predicted points (CSV, or JSON with --format json). With --mission the
    path stops at the first wall of the map, stays in free space, and the region of the final
    point is reported (CSV columns region, clipped).
    """
    _positive(horizon, "--horizon")
    _positive(step, "--step")
    _positive(history_s, "--history")
    mission = load_mission(mission_file) if mission_file is not None else None
    defaults = prediction_params(mission) if mission is not None else PredictionParams()
    name = _check_model(model or defaults.model)
    params = _mission_params(mission, name)
    horizon = horizon or defaults.horizon_s
    history_s = history_s or defaults.history_s
    _prepare_output(out, "--out")
    _prepare_output(plot, "--plot")
    full = read_csv_trajectory(track_file, min_points=2)
    history = full.last(history_s)
    dt = step or float(np.median(np.diff(full.t)))
    n = _predicted_points(horizon, dt, step is None)
    times = full.t[-1] + np.minimum(np.arange(1, n + 1) * dt, horizon)
    xy = _fit_predict(name, history, times, params, str(track_file))
    used = {k: v for k, v in vars(make_model(name, **params)).items() if not k.endswith("_")}

    clipped: ClippedPath | None = None
    regions: RegionMap | None = None
    grid: OccupancyGrid | None = None
    layout: HouseLayout | None = None
    if mission is not None:
        grid, layout, regions = _map_of(mission)
        try:
            clipped = clip_prediction(full.xy[-1], xy, grid, regions)
        except ValueError as err:
            raise UserError(f"{mission_file}: {err}") from None
    shown = clipped.xy if clipped is not None else xy

    if fmt is OutFormat.json:
        doc: dict[str, Any] = {
            "track": str(track_file),
            "model": name,
            "params": used,
            "history_s": history_s,
            "horizon_s": horizon,
            "t_last": float(full.t[-1]),
            "last_seen": [float(v) for v in full.xy[-1]],
            "points": [
                {"t": float(t), "x": float(p[0]), "y": float(p[1])}
                for t, p in zip(times, shown, strict=True)
            ],
        }
        if clipped is not None and regions is not None:
            doc["clipped"] = clipped.clipped
            doc["stop_index"] = clipped.stop_index
            doc["unclipped_end"] = [float(v) for v in xy[-1]]
            doc["region"] = clipped.region
            for point in doc["points"]:
                point["region"] = regions.locate((point["x"], point["y"]))
        text = _json_text(doc)
    else:
        text = _track_csv(times, shown, clipped, regions)

    figure: bytes | None = None
    if plot is not None:
        figure = _track_plot(full, history, times, mission, grid, layout, regions, track_file, name)

    err = _err()
    if out is not None:
        write_output(out, text)
        err.print(f"wrote {out}")
    else:
        typer.echo(text, nl=False)
    if clipped is not None:
        where = clipped.region or "no region"
        note = (
            f"stopped at a wall {times[clipped.stop_index] - full.t[-1]:.1f} s ahead"
            if clipped.stop_index is not None
            else "path is free"
        )
        end = clipped.end
        err.print(f"{name}: predicted ({end[0]:.2f}, {end[1]:.2f}) in {where}; {note}")
    if figure is not None and plot is not None:
        write_output(plot, figure)
        err.print(f"wrote {plot}")


def _track_plot(
    full: Trajectory,
    history: Trajectory,
    times: np.ndarray,
    mission: Mission | None,
    grid: OccupancyGrid | None,
    layout: HouseLayout | None,
    regions: RegionMap | None,
    track_file: Path,
    chosen: str,
) -> bytes:
    from pfctl.plots.prediction import png_bytes, prediction_figure

    predictions: dict[str, np.ndarray] = {}
    for name in MODEL_NAMES:
        if len(history) >= MIN_POINTS[name]:
            params = _mission_params(mission, name)
            predictions[name] = _fit_predict(name, history, times, params, str(track_file))
    clipped: dict[str, np.ndarray] | None = None
    region = None
    if grid is not None:
        clipped = {}
        for name, path in predictions.items():
            c = clip_prediction(full.xy[-1], path, grid, regions)
            clipped[name] = c.xy
            if name == chosen:
                region = f"{c.region or 'none'} ({chosen})"
    horizon = times[-1] - full.t[-1]
    fig = prediction_figure(
        history.xy,
        predictions,
        clipped,
        grid,
        layout,
        title=f"{track_file.name}: {horizon:.1f} s ahead",
        region=region,
    )
    return png_bytes(fig)


# --------------------------------------------------------------------------------------------
# pfctl predict evaluate


def _score_table(title: str, scores: dict[str, Score]) -> Table:
    table = Table(title=title)
    table.add_column("model")
    for col in ("ADE m", "FDE m", "n", "ms/call"):
        table.add_column(col, justify="right")
    for name, s in scores.items():
        table.add_row(name, f"{s.ade:.3f}", f"{s.fde:.3f}", str(s.n), f"{s.ms_per_call:.2f}")
    return table


@app.command("evaluate")
def evaluate_command(
    data: Annotated[
        Path,
        typer.Argument(help="A trajectory file, or a folder of them (searched recursively)."),
    ],
    fmt: Annotated[
        InFormat, typer.Option("--format", help="csv (t,x,y per file) or frames (frame ped x y).")
    ] = InFormat.frames,
    fps: Annotated[
        float | None,
        typer.Option("--fps", help="frames: annotated steps per second (2.5 → 0.4 s steps)."),
    ] = None,
    frame_step: Annotated[
        float | None,
        typer.Option("--frame-step", help="frames: frame-id increment of one step (default: gcd)."),
    ] = None,
    obs: Annotated[int, typer.Option("--obs", help="Observed samples per window.", min=2)] = 8,
    pred: Annotated[int, typer.Option("--pred", help="Predicted samples per window.", min=1)] = 12,
    jobs: Annotated[int, typer.Option("--jobs", help="Worker processes.", min=1)] = 1,
    json_out: Annotated[
        Path | None, typer.Option("--json", help="Write the scores as JSON here.")
    ] = None,
    models: Annotated[
        list[str] | None,
        typer.Option("--models", help="Models to run, e.g. svr,cv (repeatable; default: all)."),
    ] = None,
    mission_file: Annotated[
        Path | None, typer.Option("--mission", help="Take the models' settings from a mission.")
    ] = None,
) -> None:
    """ADE and FDE (m) and ms per fit+predict of every model on every window of DATA.

    A window is OBS observed samples followed by PRED predicted ones (ETH/UCY protocol: 8 and 12
    at 0.4 s). With --format frames, time = (frame − first) / frame step / FPS.
    """
    names = _model_list(models)
    mission = load_mission(mission_file) if mission_file is not None else None
    need = max(MIN_POINTS[n] for n in names)
    if obs < need:
        raise UserError(f"--obs {obs}: the models {', '.join(names)} need at least {need}")
    _prepare_output(json_out, "--json")
    tracks = _load_tracks(data, fmt, fps, frame_step)
    windows = make_windows(tracks, obs, pred)
    if len(windows) == 0:
        raise UserError(
            f"{data}: no track has {obs + pred} consecutive samples (--obs {obs} + --pred {pred})"
        )
    specs = [ModelSpec.of(n, **_mission_params(mission, n)) for n in names]
    err = _err()
    with progress_bar(err, "evaluating", len(specs) * len(windows)) as advance:
        scores = evaluate(specs, windows, jobs=jobs, progress=advance)
    title = f"{data}: {len(windows)} windows of {len(tracks)} tracks, obs {obs}, pred {pred}"
    if fps is not None:
        title += f", {fps:g} steps/s"
    _out().print(_score_table(title, scores))
    if json_out is not None:
        doc = {
            "data": str(data),
            "format": fmt.value,
            "fps": fps,
            "obs": obs,
            "pred": pred,
            "tracks": len(tracks),
            "windows": len(windows),
            "models": {name: s.as_dict() for name, s in scores.items()},
        }
        write_output(json_out, _json_text(doc))
        err.print(f"wrote {json_out}")


# --------------------------------------------------------------------------------------------
# pfctl predict search

_GRID = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*(.+)$")
DEFAULT_GRIDS: dict[str, dict[str, list[Any]]] = {
    "svr": {
        "C": [30.0, 100.0, 300.0, 1000.0],
        "gamma": [0.01, 0.03, 0.1, 0.3, 1.0],
        "epsilon": [0.01],
        "half_life_s": [0.5, 1.0, 2.0],
    },
    "svr-time": {
        "C": [100.0, 1000.0],
        "gamma": [0.01, 0.03, 0.1, 0.3, 1.0],
        "epsilon": [0.01],
        "half_life_s": [0.5, 1.0, 2.0],
    },
    "poly3": {"degree": [1, 2, 3], "half_life_s": [0.5, 1.0, 2.0]},
    "cv": {"window_s": [0.4, 0.8, 1.2, 1.6, 2.0, 2.8], "estimator": ["mean", "median"]},
}


def _grid_value(text: str) -> Any:
    text = text.strip()
    try:
        value = float(text)
    except ValueError:
        return text
    return int(value) if re.fullmatch(r"[-+]?\d+", text) else value


def _parse_grid(model: str, specs: Sequence[str] | None) -> dict[str, list[Any]]:
    if not specs:
        return DEFAULT_GRIDS[model]
    from pfctl.core.prediction.models import model_params

    known = model_params(model)
    grid: dict[str, list[Any]] = {}
    for spec in specs:
        m = _GRID.match(spec)
        if not m:
            raise UserError(f"--grid {spec!r}: expected NAME=V1,V2,... (e.g. C=10,100,1000)")
        key, values = m.group(1), [v for v in m.group(2).split(",") if v.strip()]
        if key not in known:
            raise UserError(f"--grid {spec!r}: {model} has no parameter {key}; has {known}")
        if not values:
            raise UserError(f"--grid {spec!r}: no values")
        grid[key] = [_grid_value(v) for v in values]
    return grid


@app.command("search")
def search_command(
    data: Annotated[
        list[Path],
        typer.Argument(help="One file or folder per scene (scenes are averaged, not pooled)."),
    ],
    model: Annotated[str, typer.Option("--model", help="The model to tune.")] = DEFAULT_MODEL,
    grid_specs: Annotated[
        list[str] | None,
        typer.Option("--grid", help="NAME=V1,V2,... (repeatable; default: a grid per model)."),
    ] = None,
    fmt: Annotated[InFormat, typer.Option("--format", help="csv or frames.")] = InFormat.frames,
    fps: Annotated[
        float | None, typer.Option("--fps", help="frames: annotated steps per second.")
    ] = None,
    frame_step: Annotated[
        float | None, typer.Option("--frame-step", help="frames: frame-id step (default: gcd).")
    ] = None,
    obs: Annotated[int, typer.Option("--obs", min=2)] = 8,
    pred: Annotated[int, typer.Option("--pred", min=1)] = 12,
    test_fraction: Annotated[
        float, typer.Option("--test-fraction", help="Share of the people held out for the test.")
    ] = 0.5,
    seed: Annotated[
        int, typer.Option("--seed", callback=check_seed, help="Seed of the split.")
    ] = 0,
    metric: Annotated[
        Metric, typer.Option("--metric", help="What to minimise: ade, fde or both (their mean).")
    ] = Metric.ade,
    stride: Annotated[
        int, typer.Option("--stride", help="Samples between window starts.", min=1)
    ] = 1,
    jobs: Annotated[int, typer.Option("--jobs", min=1)] = 1,
    top: Annotated[int, typer.Option("--top", help="Rows of the table.", min=1)] = 10,
    json_out: Annotated[Path | None, typer.Option("--json", help="All candidates as JSON.")] = None,
) -> None:
    """Grid search of MODEL's hyperparameters: choose on the train people, score on the test.

    Every scene's people are split (seeded) into train and test; candidates are ranked by the
    train score averaged over scenes; the best one and cv are then scored on the test people.
    """
    _check_model(model)
    grid = _parse_grid(model, grid_specs)
    if not 0.0 < test_fraction < 1.0:
        raise UserError(f"--test-fraction: expected a number in (0, 1), got {test_fraction:g}")
    _prepare_output(json_out, "--json")
    scenes: dict[str, list[Trajectory]] = {}
    for path in data:
        name = path.name or str(path)
        if name in scenes:
            name = str(path)
        scenes[name] = _load_tracks(path, fmt, fps, frame_step)
    err = _err()
    baselines = [ModelSpec.of("cv", label="cv (default)")]
    bar_state: dict[str, Any] = {}
    with Progress(
        TextColumn("searching"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,
    ) as bar:

        def advance(k: int, total: int) -> None:
            if "task" not in bar_state:
                bar_state["task"] = bar.add_task("search", total=total)
            bar.update(bar_state["task"], advance=k)

        try:
            result = grid_search(
                model,
                grid,
                scenes,
                obs=obs,
                pred=pred,
                test_fraction=test_fraction,
                seed=seed,
                metric=metric.value,
                stride=stride,
                baselines=baselines,
                jobs=jobs,
                progress=advance,
            )
        except (ValueError, PredictionError) as error:
            raise UserError(f"pfctl predict search: {error}") from None
    keys = list(grid)
    table = Table(
        title=(
            f"{model}: {len(result.candidates)} candidates, ranked by train {metric.value} "
            f"(mean over {len(scenes)} scenes; train windows {sum(result.n_train.values())}, "
            f"test windows {sum(result.n_test.values())})"
        )
    )
    for k in keys:
        table.add_column(k, justify="right")
    for col in ("train ADE", "train FDE", "test ADE", "test FDE"):
        table.add_column(col, justify="right")
    for c in result.candidates[:top]:
        test = c.test or {}
        table.add_row(
            *(str(c.params[k]) for k in keys),
            f"{c.train['ade']:.3f}",
            f"{c.train['fde']:.3f}",
            f"{test['ade']:.3f}" if test else "",
            f"{test['fde']:.3f}" if test else "",
        )
    for title, b in result.baselines.items():
        table.add_row(
            title,
            *([""] * (len(keys) - 1)),
            f"{b['train']['ade']:.3f}",
            f"{b['train']['fde']:.3f}",
            f"{b['test']['ade']:.3f}",
            f"{b['test']['fde']:.3f}",
        )
    _out().print(table)
    best = result.best
    _out().print(
        f"best {model}: "
        + ", ".join(f"{k}={best.params[k]}" for k in keys)
        + (
            f"; test ADE {best.test['ade']:.3f} m, FDE {best.test['fde']:.3f} m"
            if best.test
            else ""
        )
    )
    if json_out is not None:
        doc = {
            "model": model,
            "metric": metric.value,
            "scenes": {s: {"train": result.n_train[s], "test": result.n_test[s]} for s in scenes},
            "seed": seed,
            "test_fraction": test_fraction,
            "best": {"params": best.params, "train": best.train, "test": best.test},
            "baselines": result.baselines,
            "candidates": [{"params": c.params, "train": c.train} for c in result.candidates],
        }
        write_output(json_out, _json_text(doc))
        err.print(f"wrote {json_out}")


# --------------------------------------------------------------------------------------------
# pfctl predict experiment door


@experiment_app.command("door")
def door(
    plot: Annotated[
        Path | None, typer.Option("--plot", help="PNG: three panels, truth vs SVR vs poly3.")
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", callback=check_seed, help="Seed of the walks.")
    ] = 0,
    walks: Annotated[int, typer.Option("--walks", help="Walks per case.", min=1)] = 20,
    history_s: Annotated[
        float, typer.Option("--history", help="Seconds of walk the models see.")
    ] = 3.0,
    json_out: Annotated[
        Path | None, typer.Option("--json", help="Mean errors as JSON here.")
    ] = None,
) -> None:
    """The paper's door experiment: walks through a door, then left, straight or right, hidden.

    The models see the walk up to the door and predict it 1, 2 and 3 s later; printed is the
    mean error (m) of each model per case.
    """
    _positive(history_s, "--history")
    _prepare_output(plot, "--plot")
    _prepare_output(json_out, "--json")
    result = run_door_experiment(seed=seed, walks=walks, history_s=history_s)
    means = result.mean_errors()
    hs = result.horizons
    table = Table(title=f"door experiment: mean error (m) after the loss, {walks} walks per case")
    table.add_column("case")
    table.add_column("model")
    for h in hs:
        table.add_column(f"{h:g} s", justify="right")
    for case in CASES:
        for name in result.models:
            table.add_row(case, name, *(f"{e:.2f}" for e in means[case][name]))
        table.add_section()
    out = _out()
    out.print(table)
    err = _err()
    figure: bytes | None = None
    if plot is not None:
        from pfctl.plots.prediction import door_figure, png_bytes

        figure = png_bytes(door_figure(result, models=("svr", "svr-time", "poly3")))
    if json_out is not None:
        doc = {
            "seed": seed,
            "walks": walks,
            "history_s": history_s,
            "horizons_s": list(hs),
            "mean_error_m": means,
        }
        write_output(json_out, _json_text(doc))
        err.print(f"wrote {json_out}")
    if figure is not None and plot is not None:
        write_output(plot, figure)
        err.print(f"wrote {plot}")
