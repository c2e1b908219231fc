"""`pfctl legs`: train and evaluate the laser leg detector (§II-E).

- ``pfctl legs train [--sim-scans N] [--real DIR ...] [--seed S] [--out model.npz]``: labelled
  segments of simulated scans (and of real bags), a seeded random forest, written atomically as
  an ``.npz`` (:mod:`pfctl.core.perception.legs.model`).
- ``pfctl legs evaluate [--model M] [--real DIR] [--sim-scans N] [--seed S] [--history H]``:
  precision, recall and F1 of leg segments per data set, at 0.5–5 m and at all ranges: the
  model on held-out simulated scans (other seeds), and on the real bags cross-validated by bag
  (for each bag — each topic of a negative bag — a forest trained on the simulated scans and
  the other bags is tested on it, scan after scan, with P(leg) averaged over ``H`` scans of
  each segment's track when ``H`` > 1; simulated test scans are independent draws, scored one
  at a time).

Bad input is a :class:`pfctl.errors.UserError` (one line, exit 2). Tables go to stdout, progress
and notes to stderr.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from pfctl import __version__
from pfctl.app.leg_data import (
    ScanSequence,
    count_real_scans,
    real_bags,
    real_sequences,
    sequences_dataset,
    sim_dataset,
)
from pfctl.app.leg_models import load_leg_model, save_leg_model
from pfctl.app.perception import leg_params
from pfctl.commands import check_seed
from pfctl.core.perception.legs.detector import LegParams
from pfctl.core.perception.legs.model import LegModel
from pfctl.core.perception.legs.training import (
    EVAL_BAND,
    LegDataset,
    Score,
    concat,
    evaluate_model,
    evaluate_sequence,
    train_forest,
)
from pfctl.errors import UserError
from pfctl.files import check_output_file
from pfctl.mission import Mission, load_mission
from pfctl.progress import progress_bar

app = typer.Typer(
    help="Laser leg detector: `pfctl legs train`, `pfctl legs evaluate`.",
    no_args_is_help=True,
)

DEFAULT_MISSION = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"
#: Held-out simulated scans are drawn with the seed plus this (never a training seed).
TEST_SEED_OFFSET = 1_000_003


def _err() -> Console:
    return Console(stderr=True, width=100, soft_wrap=True)


def _out() -> Console:
    return Console(width=170, soft_wrap=True)


def _mission(path: Path | None) -> Mission:
    path = path or DEFAULT_MISSION
    if not path.is_file():
        raise UserError(f"--mission {path}: no such mission file")
    return load_mission(path)


def _check_count(value: int, option: str, minimum: int = 0) -> None:
    if value < minimum:
        raise UserError(f"{option}: expected an integer ≥ {minimum}, got {value}")


def _sim(mission: Mission, scans: int, seed: int, params: LegParams, what: str) -> LegDataset:
    with progress_bar(_err(), what, scans) as advance:
        return sim_dataset(mission, scans, seed, params, advance)


def _real(directory: Path, params: LegParams) -> LegDataset:
    return sequences_dataset(_real_sequences(directory, params))


def _real_sequences(directory: Path, params: LegParams) -> list[ScanSequence]:
    total = count_real_scans(directory)
    with progress_bar(_err(), f"reading {directory.name}", total) as advance:
        return real_sequences(directory, params, advance)


def _size_line(data: LegDataset) -> str:
    return (
        f"{data.name}: {data.scans} scans, {len(data)} segments, {data.positives} legs, "
        f"{len(data) - data.positives} non-legs ({len(data.groups)} groups)"
    )


@app.command("train")
def train_command(
    sim_scans: Annotated[
        int, typer.Option("--sim-scans", help="Simulated labelled scans to train on.")
    ] = 4000,
    real: Annotated[
        list[Path] | None,
        typer.Option("--real", help="A folder of real leg bags (repeatable)."),
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", callback=check_seed, help="Seed of the scans and the forest.")
    ] = 0,
    out: Annotated[Path, typer.Option("--out", help="The model file to write.")] = Path(
        "legs_model.npz"
    ),
    mission: Annotated[
        Path | None,
        typer.Option("--mission", help="Mission: the house and perception.legs (default: house)."),
    ] = None,
) -> None:
    """Train the leg classifier on simulated (and real) scans; write it as an .npz."""
    _check_count(sim_scans, "--sim-scans")
    check_output_file(out, "--out", make_folder=False)
    m = _mission(mission)
    params = leg_params(m)
    for directory in real or []:  # a wrong folder is refused before the simulation runs
        real_bags(directory)
    parts = []
    if sim_scans:
        parts.append(_sim(m, sim_scans, seed, params, "simulating scans"))
    for directory in real or []:
        data = _real(directory, params)
        data.name = f"real:{directory.name}"
        parts.append(data)
    if not parts:
        raise UserError("--sim-scans 0 and no --real: nothing to train on")
    for part in parts:
        typer.echo(_size_line(part))
    data = concat("train", parts)
    if data.positives == 0 or data.positives == len(data):
        raise UserError("the training data has only one class (no legs, or nothing but legs)")
    meta = {
        "pfctl_version": __version__,
        "datasets": [
            {
                "name": p.name,
                "scans": p.scans,
                "segments": len(p),
                "legs": p.positives,
                "groups": list(p.groups),
            }
            for p in parts
        ],
        "sim_scans": sim_scans,
        "real": [str(d) for d in real or []],
        "params": {
            "jump_distance": params.jump_distance,
            "min_points": params.min_points,
            "max_range": params.max_range,
        },
        "command": "pfctl legs train "
        + " ".join(
            [f"--sim-scans {sim_scans}", f"--seed {seed}"] + [f"--real {d}" for d in real or []]
        ),
    }
    with progress_bar(_err(), "training the forest", 1) as advance:
        model = train_forest(data, seed, metadata=meta)
        advance(1)
    try:
        save_leg_model(model, out)
    except OSError as err:
        raise UserError(f"--out {out}: cannot write: {err.strerror}") from None
    in_band, everywhere = evaluate_model(model, data, params.probability)
    size_kb = out.stat().st_size / 1024
    typer.echo(
        f"forest: {model.n_trees} trees, {model.n_nodes} nodes, depth {model.depth}; "
        f"{len(data)} segments ({data.positives} legs); {size_kb:.0f} kB"
    )
    typer.echo(
        f"on its training data at {EVAL_BAND[0]:g}–{EVAL_BAND[1]:g} m: "
        f"precision {in_band.precision:.3f}, recall {in_band.recall:.3f} "
        f"(all ranges: {everywhere.precision:.3f}, {everywhere.recall:.3f})"
    )
    typer.echo(f"wrote {out}")


def _fmt(value: float) -> str:
    return "–" if math.isnan(value) else f"{value:.3f}"


def _row(table: Table, name: str, band: Score, everywhere: Score) -> None:
    table.add_row(
        name,
        str(band.segments),
        str(band.tp + band.fn),
        _fmt(band.precision),
        _fmt(band.recall),
        _fmt(band.f1),
        _fmt(everywhere.precision),
        _fmt(everywhere.recall),
        _fmt(everywhere.f1),
    )


def _table(title: str) -> Table:
    t = Table(title=title)
    lo, hi = EVAL_BAND
    for col in ("data set", "segments", "legs"):
        t.add_column(col, justify="right" if col != "data set" else "left")
    for col in ("precision", "recall", "F1"):
        t.add_column(f"{col} {lo:g}–{hi:g} m", justify="right")
    for col in ("precision", "recall", "F1"):
        t.add_column(f"{col} all", justify="right")
    return t


@app.command("evaluate")
def evaluate_command(
    model: Annotated[
        Path | None,
        typer.Option("--model", help="Model to score on held-out sim scans (default: shipped)."),
    ] = None,
    real: Annotated[
        Path | None,
        typer.Option("--real", help="A folder of real leg bags: cross-validated by bag."),
    ] = None,
    sim_scans: Annotated[
        int,
        typer.Option("--sim-scans", help="Simulated scans to test on (and to train each fold on)."),
    ] = 1000,
    seed: Annotated[
        int, typer.Option("--seed", callback=check_seed, help="Seed of the training scans.")
    ] = 0,
    mission: Annotated[
        Path | None,
        typer.Option("--mission", help="Mission: the house and perception.legs (default: house)."),
    ] = None,
    history: Annotated[
        int | None,
        typer.Option(
            "--history",
            help="Real bags: average P(leg) over this many scans of each segment's track "
            "(default: the mission's perception.legs.history_scans).",
        ),
    ] = None,
    json_out: Annotated[
        Path | None, typer.Option("--json", help="Also write the figures as JSON here.")
    ] = None,
) -> None:
    """Precision, recall and F1 of leg segments per data set (0.5–5 m and all ranges)."""
    _check_count(sim_scans, "--sim-scans", 1)
    check_output_file(json_out, "--json", make_folder=False)
    m = _mission(mission)
    params = leg_params(m)
    if history is not None:
        _check_count(history, "--history", 1)
    scans = params.history_scans if history is None else history
    leg_model: LegModel = load_leg_model(model)
    if real is not None:  # a wrong folder is refused before the simulation runs
        real_bags(real)
    err = _err()
    test = _sim(m, sim_scans, seed + TEST_SEED_OFFSET, params, "simulating test scans")
    test.name = "sim (held out)"
    table = _table(f"leg segments, P(leg) ≥ {params.probability:g}")
    results: dict[str, dict[str, float]] = {}
    band, everywhere = evaluate_model(leg_model, test, params.probability)
    _row(table, f"sim, seed {seed + TEST_SEED_OFFSET} ({test.scans} scans)", band, everywhere)
    results["sim"] = _figures(band, everywhere)
    if real is not None:
        sequences = dict(_real_sequences(real, params))
        data = sequences_dataset(list(sequences.items()))
        train = _sim(m, sim_scans, seed, params, "simulating training scans")
        err.print(
            f"real: {len(data.groups)} groups, cross-validated by bag: each fold trains on "
            f"{train.scans} simulated scans and the other groups (--model is not used here)"
            + (f"; P(leg) averaged over {scans} scans of each segment's track" if scans > 1 else "")
        )
        total_b = total_a = Score(0, 0, 0, 0)
        with progress_bar(err, "cross-validating", len(data.groups)) as advance:
            for g in data.groups:
                fold = concat("train", [train, data.without_group(g)])
                fm = train_forest(fold, seed)
                if scans > 1:
                    b, a = evaluate_sequence(fm, sequences[g], params.probability, scans)
                else:
                    b, a = evaluate_model(fm, data.only_group(g), params.probability)
                _row(table, f"  {g}", b, a)
                total_b, total_a = total_b + b, total_a + a
                advance(1)
        _row(table, f"real {real.name} (all folds)", total_b, total_a)
        results["real"] = _figures(total_b, total_a) | {"history_scans": scans}
    _out().print(table)
    if json_out is not None:
        from pfctl.files import atomic_write

        try:
            atomic_write(json_out, json.dumps(results, indent=2) + "\n")
        except OSError as e:
            raise UserError(f"--json {json_out}: cannot write: {e.strerror}") from None
    if real is None:  # after the outputs: an error, if any, is the only line
        err.print("note: no --real DIR given: the real bags are not evaluated")


def _figures(band: Score, everywhere: Score) -> dict[str, float]:
    return {
        "precision": band.precision,
        "recall": band.recall,
        "f1": band.f1,
        "precision_all": everywhere.precision,
        "recall_all": everywhere.recall,
        "f1_all": everywhere.f1,
        "tp": band.tp,
        "fp": band.fp,
        "fn": band.fn,
    }
