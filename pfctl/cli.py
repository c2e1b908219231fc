"""The `pfctl` command line: registers the command groups and turns user errors into exit 2."""

from __future__ import annotations

import signal
import sys

import typer

from pfctl import __version__
from pfctl.commands import bench as bench_command
from pfctl.commands import bt as bt_commands
from pfctl.commands import follow as follow_commands
from pfctl.commands import learn_target as learn_target_command
from pfctl.commands import legs as legs_commands
from pfctl.commands import map as map_commands
from pfctl.commands import mission as mission_commands
from pfctl.commands import predict as predict_commands
from pfctl.commands import replay as replay_command
from pfctl.commands import sim as sim_commands
from pfctl.errors import UserError
from pfctl.interrupts import Interrupted, command_signals, unreported

app = typer.Typer(
    name="pfctl",
    help=(
        "Person-following with active target search: learn a person, follow them, find them again."
    ),
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
app.add_typer(mission_commands.app, name="mission")
app.add_typer(map_commands.app, name="map")
app.add_typer(sim_commands.app, name="sim")
app.add_typer(predict_commands.app, name="predict")
app.add_typer(legs_commands.app, name="legs")
app.add_typer(bt_commands.app, name="bt")
app.command("learn-target")(learn_target_command.learn_target)
app.command("follow")(follow_commands.follow)
app.command("search")(follow_commands.search)
app.command("replay")(replay_command.replay)
app.command("bench")(bench_command.bench)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"pfctl {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """Person-following with active target search."""


def main() -> None:
    """Console entry point: user errors become one line on stderr and exit status 2; SIGINT and
    SIGTERM (:mod:`pfctl.interrupts`) one line and exit status 130 or 143."""
    with command_signals():
        try:
            app()
        except UserError as err:
            sys.stderr.write(f"pfctl: error: {err}\n")
            sys.exit(err.exit_code)
        except (KeyboardInterrupt, SystemExit) as end:
            interrupt = unreported(end)
            if interrupt is None:
                if isinstance(end, SystemExit):
                    raise
                interrupt = Interrupted(signal.SIGINT)
            sys.stderr.write(interrupt.line())
            sys.exit(interrupt.exit_status)


if __name__ == "__main__":  # pragma: no cover
    main()
