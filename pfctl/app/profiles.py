"""Target profile files (``pfctl learn-target --out``, ``--target``): read and written here, the
profile itself and its ``.npz`` bytes are core's
(:class:`~pfctl.core.perception.identity.profile.TargetProfile`). A file that is not a usable
profile is a one-line :class:`~pfctl.errors.UserError` naming it.
"""

from __future__ import annotations

import os
from pathlib import Path

from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import TargetProfile
from pfctl.errors import UserError
from pfctl.files import atomic_write


def load_target_profile(path: str | os.PathLike[str]) -> TargetProfile:
    """The profile in ``path`` (written by :func:`save_target_profile` or ``pfctl learn-target``);
    a missing or bad file is a UserError naming it."""
    name = str(path)
    try:
        with open(os.fspath(path), "rb") as handle:
            data = handle.read()
    except FileNotFoundError:
        raise UserError(f"{name}: no such target profile") from None
    except OSError as err:
        raise UserError(f"{name}: not a target profile (.npz): {err}") from None
    try:
        return TargetProfile.from_bytes(data)
    except ValueError as err:
        raise UserError(f"{name}: {err}") from None


def save_target_profile(profile: TargetProfile, path: str | os.PathLike[str]) -> Path:
    """Write ``profile`` to ``path`` all or nothing; OSError if it cannot be written."""
    return atomic_write(path, profile.to_bytes())


def check_target_profile(
    profile: TargetProfile, params: IdentityParams, source: str = "profile"
) -> None:
    """A UserError (naming ``source``) unless the profile's histograms are in the colour space
    and bins of ``params``, the mission's ``perception.identity``."""
    try:
        profile.check_params(params, source)
    except ValueError as err:
        raise UserError(str(err)) from None


__all__ = ["check_target_profile", "load_target_profile", "save_target_profile"]
