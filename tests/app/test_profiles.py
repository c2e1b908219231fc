"""Target profile files: written all or nothing, read back the same; a bad file or a profile in
other bins than the mission's is one line for the user naming it."""

from __future__ import annotations

import numpy as np
import pytest

from pfctl.app.profiles import check_target_profile, load_target_profile, save_target_profile
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import PROFILE_VERSION, TargetProfile
from pfctl.errors import UserError


def _profile(faces: int = 2) -> TargetProfile:
    rng = np.random.default_rng(1)
    upper, lower = rng.random(256), rng.random(256)
    return TargetProfile(
        upper / upper.sum(), lower / lower.sum(), rng.normal(size=(faces, 128)), frames=7
    )


def test_profile_round_trips_through_npz_and_bad_files_are_user_errors(tmp_path) -> None:
    prof = _profile()
    path = save_target_profile(prof, tmp_path / "t.npz")
    back = load_target_profile(path)
    assert np.array_equal(back.upper, prof.upper) and np.array_equal(back.faces, prof.faces)
    assert (back.color_space, back.bins, back.frames) == ("hsv", (16, 4, 4), 7)
    assert load_target_profile(
        save_target_profile(_profile(0), tmp_path / "noface.npz")
    ).faces.shape == (0, 128)
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    np.savez(tmp_path / "old.npz", **{**_fields(prof), "version": np.array(PROFILE_VERSION + 1)})
    np.savez(tmp_path / "bins.npz", **{**_fields(prof), "bins": np.array([8, 4, 4])})
    np.savez(tmp_path / "part.npz", upper=prof.upper)
    obj = np.array([{"evil": 1}], dtype=object)
    np.savez(tmp_path / "pickle.npz", **{**_fields(prof), "faces": obj})
    cases = {
        "missing.npz": "no such",
        "junk.npz": "not a target profile",
        "old.npz": "version",
        "bins.npz": "upper",
        "part.npz": "missing",
        "pickle.npz": "not a target profile",
    }
    for name, words in cases.items():
        with pytest.raises(UserError, match=words) as err:
            load_target_profile(tmp_path / name)
        assert name in str(err.value) and "\n" not in str(err.value)


def _fields(prof: TargetProfile) -> dict[str, np.ndarray]:
    with np.load(__import__("io").BytesIO(prof.to_bytes())) as data:
        return {k: data[k] for k in data.files}


def test_a_profile_in_other_bins_than_the_mission_is_a_user_error() -> None:
    params = IdentityParams(clothes=ClothesParams("rgb", (8, 8, 8)))
    with pytest.raises(UserError, match=r"^t\.npz: histograms are hsv .*\(learn it again\)$"):
        check_target_profile(_profile(), params, "t.npz")
    check_target_profile(_profile(), IdentityParams())
