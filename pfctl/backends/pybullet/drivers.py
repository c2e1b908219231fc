"""Who drives the robot in ``pfctl sim run`` before the follower exists: nobody, a script, a person.

- :class:`ScriptedDriver` replays a velocity script, a CSV file with the header
  ``t,vx,vy,wz`` and optionally ``pan,tilt``: from time ``t`` (s, increasing) on, the base is
  commanded ``vx, vy`` (m/s, robot frame) and ``wz`` (rad/s), and the head is pointed at
  ``pan, tilt`` (rad); the last row holds until the end. :func:`read_velocity_script` checks the
  file and raises :class:`ScriptError` naming the file, line and column of the first problem.
- :class:`KeyboardDriver` turns key presses into velocity steps (:data:`KEYS`): each press changes
  the command by one step and the robot keeps it until the next press, because a terminal reports
  presses, not releases. Keys come from :class:`TerminalKeys` (stdin in cbreak mode) or from
  PyBullet's window (:func:`window_keys`).
"""

from __future__ import annotations

import csv
import math
import os
import select
import sys
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

import pybullet as p

from pfctl.core.robot import HeadTarget, Twist2D

#: Velocity change per key press: m/s for vx, vy and rad/s for wz.
LINEAR_STEP = 0.05
ANGULAR_STEP = 0.2
#: Key → (dvx, dvy, dwz) in steps; " " stops the base; "x" ends the run.
KEYS: dict[str, tuple[int, int, int]] = {
    "w": (1, 0, 0),
    "s": (-1, 0, 0),
    "a": (0, 1, 0),
    "d": (0, -1, 0),
    "q": (0, 0, 1),
    "e": (0, 0, -1),
}
STOP_KEY, QUIT_KEY = " ", "x"
HELP = "keys: w/s forward/back, a/d left/right, q/e turn, space stop, x quit"


class ScriptError(ValueError):
    """A velocity script that cannot be read; the message is one line naming file and line."""


@dataclass(frozen=True)
class ScriptStep:
    """From ``t`` on: this base command and, if given, this head target."""

    t: float
    base: Twist2D
    head: HeadTarget | None = None


def read_velocity_script(path: str | os.PathLike[str]) -> list[ScriptStep]:
    """The steps of a velocity script (see the module docstring)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScriptError(f"{path}: no such file (expected a velocity script CSV)") from None
    except IsADirectoryError:
        raise ScriptError(f"{path}: is a directory (expected a velocity script CSV)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise ScriptError(f"{path}: cannot read: {err}") from None
    rows = list(csv.reader(text.splitlines()))
    numbered = [
        (i + 1, [c.strip() for c in r]) for i, r in enumerate(rows) if any(c.strip() for c in r)
    ]
    if not numbered:
        raise ScriptError(f"{path}: empty (expected a header t,vx,vy,wz[,pan,tilt] and rows)")
    line, header = numbered[0]
    if header not in (["t", "vx", "vy", "wz"], ["t", "vx", "vy", "wz", "pan", "tilt"]):
        raise ScriptError(
            f"{path}:{line}: expected the header t,vx,vy,wz or t,vx,vy,wz,pan,tilt, "
            f"got {','.join(header)}"
        )
    steps: list[ScriptStep] = []
    for line, cells in numbered[1:]:
        if len(cells) != len(header):
            raise ScriptError(
                f"{path}:{line}: expected {len(header)} values ({','.join(header)}), "
                f"got {len(cells)}"
            )
        values = []
        for name, cell in zip(header, cells, strict=True):
            try:
                value = float(cell)
            except ValueError:
                raise ScriptError(
                    f"{path}:{line}: {name}: expected a number, got {cell!r}"
                ) from None
            if not math.isfinite(value):
                raise ScriptError(f"{path}:{line}: {name}: expected a finite number, got {cell}")
            values.append(value)
        t = values[0]
        if steps and t <= steps[-1].t:
            raise ScriptError(
                f"{path}:{line}: t: expected times to increase, got {t:g} after {steps[-1].t:g}"
            )
        if t < 0:
            raise ScriptError(f"{path}:{line}: t: expected a time ≥ 0 s, got {t:g}")
        head = HeadTarget(values[4], values[5]) if len(values) == 6 else None
        steps.append(ScriptStep(t, Twist2D(values[1], values[2], values[3]), head))
    if not steps:
        raise ScriptError(f"{path}: no rows after the header (expected t,vx,vy,wz values)")
    return steps


class ScriptedDriver:
    """Replays script steps: :meth:`command` gives the step in force at time ``t``."""

    quit = False

    def __init__(self, steps: list[ScriptStep]) -> None:
        self.steps = steps

    def command(self, t: float) -> ScriptStep | None:
        """The step in force at ``t`` (None before the first)."""
        current = None
        for step in self.steps:
            if step.t > t + 1e-9:
                break
            current = step
        return current


class KeyboardDriver:
    """Velocity steps from key presses, within ``max_linear`` / ``max_angular``."""

    def __init__(self, max_linear: float, max_angular: float) -> None:
        self.max_linear, self.max_angular = max_linear, max_angular
        self.base = Twist2D()
        self.quit = False

    def press(self, keys: str) -> None:
        """Apply the presses in ``keys`` in order."""
        for key in keys.lower():
            if key == QUIT_KEY:
                self.quit = True
            elif key == STOP_KEY:
                self.base = Twist2D()
            elif key in KEYS:
                dvx, dvy, dwz = KEYS[key]
                b, lin, ang = self.base, self.max_linear, self.max_angular
                self.base = Twist2D(
                    min(max(b.vx + dvx * LINEAR_STEP, -lin), lin),
                    min(max(b.vy + dvy * LINEAR_STEP, -lin), lin),
                    min(max(b.wz + dwz * ANGULAR_STEP, -ang), ang),
                )

    def command(self, t: float) -> ScriptStep:
        return ScriptStep(t, self.base)


class TerminalKeys:
    """Key presses from a terminal's stdin, unbuffered and unechoed (cbreak mode) while open."""

    def __init__(self) -> None:
        self._fd = sys.stdin.fileno()
        self._saved: list | None = None

    def __enter__(self) -> TerminalKeys:
        import termios
        import tty

        self._saved = termios.tcgetattr(self._fd)
        tty.setcbreak(self._fd)  # keys arrive one by one; Ctrl-C still interrupts
        return self

    def read(self) -> str:
        """The keys pressed since the last call (never blocks)."""
        out = []
        while select.select([self._fd], [], [], 0)[0]:
            data = os.read(self._fd, 64)
            if not data:
                break
            out.append(data.decode("utf-8", "ignore"))
        return "".join(out)

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        import termios

        if self._saved is not None:
            termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)


def window_keys(client: int) -> str:
    """The keys pressed in PyBullet's window since the last call."""
    events = p.getKeyboardEvents(physicsClientId=client)
    return "".join(
        chr(k) for k, state in events.items() if state & p.KEY_WAS_TRIGGERED and 0 < k < 128
    )


__all__ = [
    "HELP",
    "KEYS",
    "KeyboardDriver",
    "ScriptError",
    "ScriptStep",
    "ScriptedDriver",
    "TerminalKeys",
    "read_velocity_script",
    "window_keys",
]
