"""Leg model files: written all or nothing, read back the same; a missing, foreign, damaged or
other-featured file is one line for the user naming it; the shipped model loads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.app.leg_models import (
    LegModelError,
    load_leg_model,
    read_leg_model,
    save_leg_model,
    shipped_model_path,
)
from pfctl.core.perception.legs.features import FEATURE_NAMES
from pfctl.core.perception.legs.model import LegModel
from pfctl.errors import UserError
from tests.core.perception.legs.test_detector import _forest


def test_a_model_file_round_trips_and_matches_sklearn(tmp_path: Path) -> None:
    forest, x = _forest()
    model = LegModel.from_forest(forest, FEATURE_NAMES, {"seed": 0})
    path = save_leg_model(model, tmp_path / "m.npz")
    loaded = read_leg_model(path, FEATURE_NAMES)
    assert loaded.metadata == {"seed": 0}
    assert loaded.n_trees == 7
    np.testing.assert_allclose(loaded.predict_proba(x), forest.predict_proba(x)[:, 1], atol=1e-6)
    with np.load(path, allow_pickle=False) as data:  # plain arrays only
        assert int(data["version"]) == 1


def test_foreign_or_corrupt_model_files_are_user_errors(tmp_path: Path) -> None:
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip at all")
    with pytest.raises(UserError, match=r"bad.npz: not a leg model"):
        read_leg_model(bad)
    other = tmp_path / "other.npz"
    np.savez(other, weights=np.zeros(3))
    with pytest.raises(LegModelError, match=r"other.npz: not a leg model"):
        read_leg_model(other)
    with pytest.raises(UserError, match="no such leg model"):
        read_leg_model(tmp_path / "missing.npz")
    forest, _ = _forest()
    names = tuple(f"f{i}" for i in range(len(FEATURE_NAMES)))
    save_leg_model(LegModel.from_forest(forest, names, {}), tmp_path / "f.npz")
    with pytest.raises(UserError, match="trained on features f0, f1"):
        read_leg_model(tmp_path / "f.npz", FEATURE_NAMES)
    with pytest.raises(UserError, match=r"f.npz"):
        load_leg_model(tmp_path / "f.npz")
    for err in (LegModelError("x"),):
        assert "\n" not in str(err)


def test_model_with_broken_arrays_is_refused(tmp_path: Path) -> None:
    forest, _ = _forest()
    model = LegModel.from_forest(forest, FEATURE_NAMES, {})
    path = save_leg_model(model, tmp_path / "m.npz")
    with np.load(path, allow_pickle=False) as data:
        arrays = dict(data)
    arrays["left"] = arrays["left"] + 10_000
    np.savez(tmp_path / "broken.npz", **arrays)
    with pytest.raises(UserError, match=r"broken.npz: damaged leg model"):
        read_leg_model(tmp_path / "broken.npz")


def test_the_shipped_model_loads() -> None:
    assert shipped_model_path().is_file()
    assert load_leg_model(None).feature_names == FEATURE_NAMES
