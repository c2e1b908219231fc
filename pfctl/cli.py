"""The `pfctl` command line: registers the command groups and turns user errors into exit 2."""

from __future__ import annotations

import signal
import sys

import typer

try:  # typer 0.2x carries its own copy of click
    from typer._click.exceptions import ClickException, MissingParameter, NoArgsIsHelpError
except ImportError:  # pragma: no cover - older typer uses click itself
    from click.exceptions import ClickException, MissingParameter, NoArgsIsHelpError

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
from pfctl.commands import track as track_commands
from pfctl.errors import UserError
from pfctl.interrupts import Interrupted, behind, command_signals, unreported

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
app.add_typer(track_commands.app, name="track")
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


def _run_app() -> None:
    """Run the app; a usage error (unknown option, value out of range, missing argument) is one
    line ``pfctl: error: COMMAND: what is wrong; see --help`` and exit status 2, not the framework's
    box. Running without arguments still prints the help."""
    try:
        status = app(standalone_mode=False)
    except NoArgsIsHelpError as err:  # typer has printed the help already (rich)
        if err.format_message().strip():
            err.show()
        sys.exit(err.exit_code)
    except ClickException as err:
        sys.stderr.write(f"pfctl: error: {_usage_line(err)}\n")
        sys.exit(err.exit_code)
    except typer.Abort:
        sys.stderr.write("pfctl: aborted\n")
        sys.exit(1)
    sys.exit(status if isinstance(status, int) else 0)


def _usage_line(err: ClickException) -> str:
    message = " ".join(err.format_message().split()).rstrip(".")
    param = getattr(err, "param", None)
    is_argument = param is not None and param.param_type_name == "argument" and param.name
    if isinstance(err, MissingParameter) and is_argument:  # as the usage line has it: MISSION
        message = f"Missing argument {param.name.upper()}"
    ctx = getattr(err, "ctx", None)
    names: list[str] = []
    while ctx is not None and ctx.parent is not None:
        names.append(ctx.info_name or "")
        ctx = ctx.parent
    if not names:
        return f"{message}; see pfctl --help"
    command = " ".join(reversed(names))
    return f"{command}: {message}; see pfctl {command} --help"


def main() -> None:
    """Console entry point: user errors become one line on stderr and exit status 2; SIGINT and
    SIGTERM (:mod:`pfctl.interrupts`) one line and exit status 130 or 143, also when the
    signal's exception surfaced as another (:func:`pfctl.interrupts.behind`)."""
    with command_signals(ending=True):
        try:
            _run_app()
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
        except Exception as err:
            interrupt = behind(err)
            if interrupt is None:
                raise
            sys.stderr.write(interrupt.line())
            sys.exit(interrupt.exit_status)


if __name__ == "__main__":  # pragma: no cover
    main()
