"""The results file of a campaign: one JSON object per finished episode, and resuming from it.

``OUT/results.jsonl`` gets a line per episode as the episode ends — written, flushed and
``fsync``'d before the next one is taken — so a campaign stopped in any way keeps every episode
that finished. ``OUT/campaign.json`` holds the configuration the fingerprint was made of
(:meth:`pfctl.bench.plan.Campaign.config`), to say what differs when a resume is refused.

Resuming (:func:`open_results` with ``resume``) reads the records, refuses a file written by a
campaign of another fingerprint (one line saying what changed), drops a last line cut short by a
crash (saying so in one line: the file, the line, that its episode runs again), and returns the
episodes already done: those whose last record is ``ok``. Episodes that
ended in ``error`` or ``timeout`` run again; their new record follows the old one (the last record
of an episode is the one that counts).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from pfctl.bench.plan import Campaign
from pfctl.errors import UserError
from pfctl.files import atomic_write

__all__ = [
    "CAMPAIGN_FILE",
    "RESULTS_FILE",
    "ResultsWriter",
    "episode_key",
    "latest",
    "open_results",
    "read_records",
]

RESULTS_FILE = "results.jsonl"
CAMPAIGN_FILE = "campaign.json"

Key = tuple[str, str, int]


def episode_key(record: dict[str, Any]) -> Key:
    """A record's episode identity: (mission file, variant, seed)."""
    return (str(record["mission_file"]), str(record["variant"]), int(record["seed"]))


def _json_default(value: Any) -> Any:
    """numpy scalars (and anything with ``item()``) as plain Python values."""
    item = getattr(value, "item", None)
    if callable(item):
        return item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def read_records(path: Path) -> tuple[list[dict[str, Any]], int]:
    """The records of a results file and the byte length of its complete lines.

    A last line without its newline (the writer was killed mid-line) is left out; any other
    line that is not a record is an error.

    Raises:
        UserError: an unreadable file or a bad line (``FILE:LINE: ...``).
    """
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise UserError(f"{path}: cannot read: {err.strerror or err}") from None
    complete = raw.rfind(b"\n") + 1
    records: list[dict[str, Any]] = []
    for number, line in enumerate(raw[:complete].splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
            episode_key(record)
        except (ValueError, KeyError, TypeError):
            raise UserError(
                f"{path}:{number}: not an episode record of pfctl bench; "
                "is this the results file of a campaign?"
            ) from None
        records.append(record)
    return records, complete


def latest(records: Iterable[dict[str, Any]]) -> dict[Key, dict[str, Any]]:
    """The last record of each episode."""
    out: dict[Key, dict[str, Any]] = {}
    for record in records:
        out[episode_key(record)] = record
    return out


@dataclass
class ResultsWriter:
    """Appends records to the results file, each synced to disk before :meth:`append` returns."""

    path: Path
    _file: IO[str] | None = None

    def append(self, record: dict[str, Any]) -> None:
        """Write ``record`` as one line; flush and fsync. Raises OSError."""
        if self._file is None:
            new = not self.path.exists()
            self._file = self.path.open("a", encoding="utf-8")
            if new:
                _fsync_dir(self.path.parent)
        self._file.write(json.dumps(record, default=_json_default) + "\n")
        self._file.flush()
        os.fsync(self._file.fileno())

    def close(self) -> None:
        """Close the file (records are already on disk)."""
        if self._file is not None:
            self._file.close()
            self._file = None


def _line_count(path: Path) -> int:
    """The number of lines of ``path`` (newlines)."""
    with path.open("rb") as f:
        return sum(chunk.count(b"\n") for chunk in iter(lambda: f.read(1 << 20), b""))


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def open_results(
    out: Path, campaign: Campaign, resume: bool, say: Callable[[str], None] = print
) -> tuple[list[dict[str, Any]], ResultsWriter]:
    """Check ``out`` for ``campaign`` and get ready to append: the records already there (when
    resuming; empty otherwise) and the writer. Writes ``campaign.json``. ``say`` gets the line
    that tells of a last line cut short and dropped.

    Raises:
        UserError: ``out`` is not a folder or cannot be written; results are there already and
            ``resume`` is off; or they come from another configuration.
    """
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: exists and is not a directory")
    results = out / RESULTS_FILE
    records: list[dict[str, Any]] = []
    if results.exists():
        records, complete = read_records(results)
        if records and not resume:
            raise UserError(
                f"--out {out}: holds the results of a campaign ({len(records)} episodes); "
                "continue it with --resume, or choose another --out"
            )
        foreign = next((r for r in records if r.get("config") != campaign.fingerprint), None)
        if foreign is not None:
            raise UserError(
                f"--resume: {results} was written by a different campaign "
                f"({_what_differs(out / CAMPAIGN_FILE, campaign)}); resume with the same "
                "missions, --vary, --task, --seed and --duration, or choose another --out"
            )
        if complete < results.stat().st_size:  # a line cut short: drop it before appending
            try:
                os.truncate(results, complete)
            except OSError as err:
                raise UserError(f"{results}: cannot repair: {err.strerror or err}") from None
            say(
                f"{results}:{_line_count(results) + 1}: the last line was cut short (the "
                "campaign was stopped while writing it); dropped it, its episode runs again"
            )
    try:
        out.mkdir(parents=True, exist_ok=True)
        atomic_write(
            out / CAMPAIGN_FILE,
            json.dumps({**campaign.config(), "fingerprint": campaign.fingerprint}, indent=2) + "\n",
        )
    except OSError as err:
        raise UserError(f"--out {out}: cannot write: {err.strerror or err}") from None
    return records, ResultsWriter(results)


def _what_differs(path: Path, campaign: Campaign) -> str:
    """What the campaign described in ``path`` has that ``campaign`` has not, in a few words."""
    try:
        old = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return f"its records' configuration is not {campaign.fingerprint}"
    new = campaign.config()
    changes = []
    for key, flag in (("task", "--task"), ("duration_s", "--duration"), ("seed", "--seed")):
        if old.get(key) != new[key]:
            changes.append(f"{flag} {old.get(key)} now {new[key]}")
    old_groups = {(g["file"], g["variant"]): g["digest"] for g in old.get("groups", [])}
    new_groups = {(g["file"], g["variant"]): g["digest"] for g in new["groups"]}
    for (file, variant), digest in new_groups.items():
        if (file, variant) not in old_groups:
            changes.append(f"{file} [{variant}] was not in it")
        elif old_groups[(file, variant)] != digest:
            changes.append(f"{file} [{variant}] has changed since")
    for file, variant in old_groups:
        if (file, variant) not in new_groups:
            changes.append(f"{file} [{variant}] is not in this one")
    return "; ".join(changes[:3]) + ("; ..." if len(changes) > 3 else "") if changes else "?"
