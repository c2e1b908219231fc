"""The oracle baseline's privileged input (issue 22, item 4): the truth reaches the follower only
for a tree that names ``oracle_search``, only in the simulator; on the real robot such a tree is
one line and exit 2 (``follow``/``search --backend hsr`` before anything connects, ``mission
validate`` for a mission that configures ``backend.hsr``), and a run on a real robot refuses it
too."""

from __future__ import annotations

from pathlib import Path

import pytest

from pfctl.app.episodes import run_episode
from pfctl.app.oracle import privileged_leaves, refuse_on_real_robot, true_target_reader
from pfctl.core.perception.identity.profile import TargetProfile
from pfctl.core.robot import GroundTruth, PersonTruth, Pose2D
from pfctl.errors import UserError
from pfctl.mission import load_mission
from tests.conftest import run_cli

MISSIONS = Path(__file__).resolve().parents[2] / "missions"
ORACLE = MISSIONS / "baselines" / "house_oracle.yaml"


def test_only_a_tree_with_the_oracle_is_privileged() -> None:
    assert privileged_leaves(load_mission(ORACLE)) == ["oracle_search"]
    for name in ("house.yaml", "baselines/house_last_seen.yaml", "baselines/house_reactive.yaml"):
        mission = load_mission(MISSIONS / name)
        assert privileged_leaves(mission) == []
        refuse_on_real_robot(mission, name)  # no error
    with pytest.raises(UserError, match=r"^x\.yaml: behavior\.tree: oracle_search .*--backend sim"):
        refuse_on_real_robot(load_mission(ORACLE), "x.yaml")


def test_the_reader_gives_the_targets_true_position_and_nothing_else() -> None:
    people = (
        PersonTruth("bob", 1.0, 2.0, 0.0, 0.5),
        PersonTruth("alice", 3.0, 4.0, 1.0, 0.7, is_target=True),
    )
    truth = GroundTruth(0.0, Pose2D(0.0, 0.0), people)
    assert true_target_reader(lambda: truth)() == (3.0, 4.0)
    no_target = GroundTruth(0.0, Pose2D(0.0, 0.0), people[:1])
    assert true_target_reader(lambda: no_target)() is None


def test_a_real_robot_run_refuses_the_oracle_before_it_starts() -> None:
    class Untouchable:
        def __getattr__(self, name: str) -> None:
            raise AssertionError(f"the robot was used: {name}")

    with pytest.raises(UserError, match="oracle_search"):
        run_episode(
            load_mission(ORACLE),
            Untouchable(),  # type: ignore[arg-type]
            TargetProfile.__new__(TargetProfile),
            1.0,
            detector=None,
            now=lambda: 0.0,
            truth=None,
            kind="real",
        )


@pytest.mark.parametrize("command", ["follow", "search"])
def test_the_hsr_backend_refuses_the_oracle_in_one_line(
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out, target = tmp_path / "out", tmp_path / "target.npz"
    target.write_bytes(b"")  # never read: the tree is refused first
    args = [command, str(ORACLE), "--backend", "hsr", "--target", str(target), "--out", str(out)]
    code, stdout, err = run_cli(args, capsys, monkeypatch)
    assert code == 2 and stdout == ""
    assert err.splitlines() == [
        f"pfctl: error: {ORACLE}: behavior.tree: oracle_search reads the simulator's ground "
        "truth (privileged, the oracle baseline): it runs only with --backend sim"
    ]
    assert not out.exists()


def test_mission_validate_refuses_the_oracle_in_a_mission_for_the_robot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = tmp_path / "robot.yaml"
    robot.write_text(f"extends: {ORACLE}\nname: on-the-robot\nbackend:\n  hsr: {{laser: /scan}}\n")
    code, stdout, err = run_cli(["mission", "validate", str(robot)], capsys, monkeypatch)
    assert code == 2 and stdout == ""
    (line,) = err.splitlines()
    assert line.startswith("pfctl: error: ") and "behavior.tree" in line, line
    assert "oracle_search reads the simulator's ground truth" in line
    assert "backend.hsr" in line
    code, stdout, _ = run_cli(["mission", "validate", str(ORACLE)], capsys, monkeypatch)
    assert code == 0 and stdout.startswith(f"OK {ORACLE}")
