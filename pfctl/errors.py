"""Errors a user can cause. The CLI turns each into one line on stderr and exit status 2."""

from __future__ import annotations


class UserError(Exception):
    """Bad input from the user (file, field, value). Its message is one self-contained line."""

    exit_code = 2


class MissionError(UserError):
    """A mission YAML that cannot be loaded: names the file, the key path and what was expected."""
