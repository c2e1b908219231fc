"""Target profile files: written all or nothing, read back the same; a bad file or a profile in
other bins than the mission's is one line for the user naming it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pfctl.app.profiles import check_target_profile, load_target_profile, save_target_profile
from pfctl.core.perception.clothes import ClothesParams
from pfctl.core.perception.identity.params import IdentityParams
from pfctl.core.perception.identity.profile import PROFILE_VERSION, TargetProfile
from pfctl.errors import UserError
from tests.conftest import run_cli

HOUSE = Path(__file__).resolve().parents[2] / "missions" / "house.yaml"


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
    np.savez(tmp_path / "text.npz", **{**_fields(prof), "version": np.array("one")})
    obj = np.array([{"evil": 1}], dtype=object)
    np.savez(tmp_path / "pickle.npz", **{**_fields(prof), "faces": obj})
    cases = {
        "missing.npz": "no such",
        "junk.npz": "not a target profile",
        "old.npz": "version",
        "bins.npz": "upper",
        "part.npz": "missing",
        "pickle.npz": "not a target profile",
        "text.npz": "version: expected integers",
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


def _bad_profiles(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """Files a user might pass as ``--target``, and the words their one error line says."""
    good = _profile().to_bytes()
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(good[:3000])  # head -c 3000 t.npz
    noise = tmp_path / "noise.npz"
    noise.write_bytes(np.random.default_rng(0).bytes(5000))
    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, **{**_fields(_profile()), "faces": np.array([{"evil": 1}], dtype=object)})
    empty = tmp_path / "empty.npz"  # numpy's EOFError was click's "Aborted!", exit 1
    empty.write_bytes(b"")
    return {
        "empty": (empty, "not a target profile: not an .npz archive"),
        "truncated": (truncated, "damaged target profile (.npz): truncated or corrupt archive"),
        "noise": (noise, "not a target profile: not an .npz archive"),
        "pickled": (pickled, "not a target profile: an array holds pickled Python objects"),
    }


@pytest.mark.parametrize("kind", ["truncated", "noise", "pickled", "empty"])
@pytest.mark.parametrize(
    "command",
    [
        ["follow", str(HOUSE), "--backend", "sim", "--duration", "5"],
        ["search", str(HOUSE), "--backend", "sim", "--duration", "5"],
        ["replay", "episode.bag"],
    ],
    ids=["follow", "search", "replay"],
)
def test_a_damaged_or_foreign_target_file_is_one_line_for_every_command(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    command: list[str],
    kind: str,
) -> None:
    path, words = _bad_profiles(tmp_path)[kind]
    out = tmp_path / "out"
    code, stdout, err = run_cli(
        [*command, "--target", str(path), "--out", str(out)], capsys, monkeypatch
    )
    assert code == 2 and stdout == ""
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert err.startswith("pfctl: error: ") and str(path) in err and words in err, err
    assert "allow_pickle" not in err
    assert not out.exists()
