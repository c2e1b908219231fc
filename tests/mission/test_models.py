"""The mission YAML: the shipped mission loads, defaults fill a minimal one, and every broken
mission ends in one `pfctl: error: <file>:<line>: <key.path>: <expected>` line with exit status 2.

Most CLI cases run in-process through :func:`pfctl.cli.main` (what the console script calls);
a few run `python -m pfctl` in a subprocess to pin down the real user-visible contract.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from pfctl.core.mapping.house import HouseLayout
from pfctl.errors import MissionError
from pfctl.mission import (
    Mission,
    TreeNode,
    dump_json_schema,
    load_mission,
    loads_mission,
)
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
HOUSE = ROOT / "missions" / "house.yaml"

# A small mission with every kind of cross-reference; the line numbers below refer to it.
BASE = """\
name: small
map:
  regions:
    - {name: kitchen, polygon: [[0, 0], [4, 0], [4, 3], [0, 3]]}
    - {name: hall, polygon: [[4, 0], [6, 0], [6, 3], [4, 3]]}
    - {name: office, polygon: [[0, 3], [4, 3], [4, 6], [0, 6]]}
  doors:
    - {between: [kitchen, hall], segment: [[4, 1], [4, 2]]}
    - {between: [kitchen, office], segment: [[1, 3], [2, 3]]}
behavior:
  tree:
    fallback:
      children:
        - condition: target_visible
        - action: waypoint_search
scenario:
  target: alice
  people:
    - name: alice
      clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}
      route: [kitchen, hall, [1.0, 4.5]]
"""

MINIMAL = """\
name: tiny
map:
  regions:
    - {name: room, polygon: [[0, 0], [3, 0], [3, 2], [0, 2]]}
"""


def run_subprocess(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    """Run ``python -m pfctl ARGS`` for real."""
    return subprocess.run(
        [sys.executable, "-m", "pfctl", *args], cwd=cwd, capture_output=True, text=True, timeout=60
    )


def assert_one_error_line(err: str, prefix: str, *fragments: str) -> None:
    """Exactly one line on stderr, starting with ``prefix`` and containing each fragment."""
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(prefix), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def edit(old: str, new: str) -> str:
    """BASE with one exact, unique piece of text replaced."""
    assert BASE.count(old) == 1, old
    return BASE.replace(old, new)


# --------------------------------------------------------------------------------------------
# valid missions
# --------------------------------------------------------------------------------------------


def test_shipped_mission_validates_with_five_regions_and_five_doors() -> None:
    mission = load_mission(HOUSE)
    layout = mission.layout()
    assert isinstance(layout, HouseLayout)
    assert [r.name for r in layout.regions] == [
        "kitchen",
        "living_room",
        "hall",
        "office",
        "bedroom",
    ]
    assert len(layout.doors) == 5
    assert len(layout.obstacles) == 6
    assert layout.doors[0].between == ("kitchen", "living_room")
    assert layout.doors[0].segment == ((5.0, 1.5), (5.0, 2.4))
    assert layout.region("kitchen").polygon == ((0.0, 0.0), (5.0, 0.0), (5.0, 4.0), (0.0, 4.0))
    assert all(type(c) is float for r in layout.regions for p in r.polygon for c in p)
    assert mission.behavior.tree.size() == 10
    assert mission.scenario.target == "alice"
    assert mission.prediction.svr.C == 1000.0
    assert mission.start_pose() == (1.0, 3.3, 0.0)


def test_validate_command_prints_ok_summary(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["mission", "validate", str(HOUSE)], capsys, monkeypatch)
    assert code == 0, err
    assert out == f"OK {HOUSE}: 5 regions, 5 doors, 6 obstacles, tree of 10 nodes\n"
    assert err == ""


def test_minimal_mission_gets_hsr_defaults_and_the_paper_tree(tmp_path: Path) -> None:
    path = tmp_path / "tiny.yaml"
    path.write_text(MINIMAL)
    mission = load_mission(path)
    assert mission.name == "tiny"
    assert mission.description is None
    assert mission.map.resolution == 0.05
    assert mission.map.occupancy is None
    assert mission.map.sensor_model.p_hit == 0.7
    assert mission.map.doors == () and mission.map.obstacles == ()
    assert mission.robot.radius == 0.215
    assert mission.robot.max_linear_speed == 0.22
    assert mission.robot.head_pan_limits == (-3.84, 1.75)
    assert mission.prediction.model == "svr"
    assert mission.prediction.weighting.kind == "exponential"
    assert mission.search.min_frontier_cells == 5
    assert mission.behavior.tick_hz == 10
    assert mission.behavior.tree.kind == "fallback"
    assert [n.label for n in mission.behavior.tree.walk() if n.is_leaf] == [
        "target_visible",
        "follow_target",
        "prediction_available",
        "go_to_prediction",
        "look_around",
        "waypoint_search",
    ]
    assert mission.scenario.people == () and mission.scenario.target is None
    x, y, _ = mission.start_pose()
    assert 0 < x < 3 and 0 < y < 2


def test_base_mission_is_valid_and_its_default_sections_match_the_house() -> None:
    mission = loads_mission(BASE)
    house = load_mission(HOUSE)
    assert mission.layout().doors[1].between == ("kitchen", "office")
    assert mission.scenario.people[0].route == ("kitchen", "hall", (1.0, 4.5))
    # The shipped mission spells out the HSR defaults: the two must not drift apart.
    for section in ("perception", "tracking", "belief", "prediction", "search"):
        assert getattr(mission, section) == getattr(house, section), section
    assert mission.map.sensor_model == house.map.sensor_model
    assert mission.robot.model_copy(update={"start": None}) == house.robot.model_copy(
        update={"start": None}
    )


def test_polygon_may_repeat_its_first_point_and_is_stored_open() -> None:
    text = MINIMAL.replace("[0, 2]]", "[0, 2], [0, 0]]")
    mission = loads_mission(text)
    assert mission.map.regions[0].polygon == ((0, 0), (3, 0), (3, 2), (0, 2))


def test_occupancy_is_resolved_relative_to_the_mission_file(tmp_path: Path) -> None:
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "house.yaml").write_text("image: house.pgm\nresolution: 0.05\n")
    (tmp_path / "maps" / "house.pgm").write_bytes(b"P5\n4 4\n255\n" + bytes([254]) * 16)
    path = tmp_path / "m.yaml"
    path.write_text(MINIMAL.replace("map:\n", "map:\n  occupancy: maps/house.yaml\n"))
    mission = load_mission(path)
    assert mission.map.occupancy == (tmp_path / "maps" / "house.yaml").resolve()


def test_tree_with_decorators_and_parallel() -> None:
    text = edit(
        "        - action: waypoint_search\n",
        "        - parallel:\n"
        "            policy: success_on_one\n"
        "            children:\n"
        "              - retry: {attempts: 3, child: {action: waypoint_search}}\n"
        "              - timeout:\n"
        "                  {seconds: 2.5, child: {action: look_around, params: {pan: 2}}}\n"
        "              - inverter: {child: {condition: target_visible}}\n",
    )
    tree = loads_mission(text).behavior.tree
    assert tree.size() == 9
    parallel = tree.children[1]
    assert parallel.kind == "parallel"
    assert [c.kind for c in parallel.children] == ["retry", "timeout", "inverter"]
    assert parallel.children[1].children[0].params == {"pan": 2}


def test_models_are_frozen() -> None:
    mission = loads_mission(MINIMAL)
    with pytest.raises(ValueError):
        mission.name = "other"  # type: ignore[misc]


def test_tree_node_is_usable_alone() -> None:
    node = TreeNode.model_validate({"sequence": {"name": "s", "children": [{"action": "stop"}]}})
    assert node.label == "s"
    assert node.children[0].body == "stop"
    with pytest.raises(ValueError, match="unknown action 'go'"):
        TreeNode.model_validate({"sequence": {"children": [{"action": "go"}]}})


def test_person_keypoints_replace_the_person_labels(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """backend.hsr: the labels are the default person source; setting person_keypoints makes
    the keypoints the source (labels null, not subscribed); naming both is an error."""
    hsr = loads_mission(MINIMAL).backend.hsr
    assert (hsr.person_labels, hsr.person_keypoints) == ("/pfctl/person_labels", None)
    keypoints = "backend:\n  hsr:\n    person_keypoints: /pfctl/person_keypoints\n"
    hsr = loads_mission(MINIMAL + keypoints).backend.hsr
    assert (hsr.person_labels, hsr.person_keypoints) == (None, "/pfctl/person_keypoints")
    hsr = loads_mission(MINIMAL + keypoints + "    person_labels: null\n").backend.hsr
    assert (hsr.person_labels, hsr.person_keypoints) == (None, "/pfctl/person_keypoints")
    both = tmp_path / "both.yaml"
    both.write_text(
        edit(
            "name: small\n",
            "name: small\n"
            + keypoints.replace(
                "    person_keypoints",
                "    person_labels: /pfctl/person_labels\n    person_keypoints",
            ),
        )
    )
    code, out, err = run_cli(["mission", "validate", str(both)], capsys, monkeypatch)
    assert code == 2 and out == ""
    assert_one_error_line(
        err,
        f"pfctl: error: {both}:5: backend.hsr.person_keypoints: expected one person source, got "
        "person_labels (/pfctl/person_labels) as well: leave person_labels out (or null)",
    )


# --------------------------------------------------------------------------------------------
# broken missions through the CLI: exit 2, one line, file:line: key.path: expected
# --------------------------------------------------------------------------------------------

BROKEN = [
    pytest.param(
        "  doors:\n",
        "  colour: red\n  doors:\n",
        7,
        "map.colour",
        ["unknown key", "wall_thickness"],
        id="unknown-key",
    ),
    pytest.param(
        "map:\n",
        "map:\n  resolution: fine\n",
        3,
        "map.resolution",
        ["expected a valid number", "'fine'"],
        id="wrong-type",
    ),
    pytest.param(
        "[[4, 0], [6, 0], [6, 3], [4, 3]]",
        "[[4, 0], [6, 0]]",
        5,
        "map.regions[1].polygon",
        ["at least 3 distinct", "got 2"],
        id="polygon-two-points",
    ),
    pytest.param(
        "[[4, 0], [6, 0], [6, 3], [4, 3]]",
        "[[4, 0], [6, 0], [4, 0]]",
        5,
        "map.regions[1].polygon",
        ["at least 3 distinct", "got 2"],
        id="polygon-closed-two-points",
    ),
    pytest.param(
        "[[4, 0], [6, 0], [6, 3], [4, 3]]",
        "[[4, 0], [6, 3], [6, 0], [4, 3]]",
        5,
        "map.regions[1].polygon",
        ["simple polygon", "self-intersection at (5, 1.5)"],
        id="polygon-self-intersecting",
    ),
    pytest.param(
        "[[4, 0], [6, 0], [6, 3], [4, 3]]",
        "[[3, 0], [6, 0], [6, 3], [3, 3]]",
        5,
        "map.regions[1].polygon",
        ["region 'hall' overlaps region 'kitchen' by 3 m²", "(+1 more)"],
        id="regions-overlap",
    ),
    pytest.param(
        "{name: office",
        "{name: kitchen",
        6,
        "map.regions[2].name",
        ["duplicate region name 'kitchen'", "regions[0]"],
        id="duplicate-region-names",
    ),
    pytest.param(
        "[kitchen, hall]",
        "[kitchen, garage]",
        8,
        "map.doors[0].between",
        ["unknown region 'garage' (regions: kitchen, hall, office)"],
        id="door-unknown-region",
    ),
    pytest.param(
        "[kitchen, hall]",
        "[hall, hall]",
        8,
        "map.doors[0].between",
        ["two different regions"],
        id="door-same-region",
    ),
    pytest.param(
        "[[4, 1], [4, 2]]",
        "[[4.5, 1], [4.5, 2]]",
        8,
        "map.doors[0].segment",
        ["wall shared by 'kitchen' and 'hall'"],
        id="door-off-the-wall",
    ),
    pytest.param(
        "[kitchen, office], segment: [[1, 3], [2, 3]]",
        "[hall, office], segment: [[4, 3], [4, 3.5]]",
        9,
        "map.doors[1].segment",
        ["'hall' and 'office' share no wall"],
        id="door-regions-not-adjacent",
    ),
    pytest.param(
        "target: alice",
        "target: carol",
        17,
        "scenario.target",
        ["one of the people (alice)", "'carol'"],
        id="target-not-among-people",
    ),
    pytest.param(
        "target: alice",
        "seed: -1\n  target: alice",
        17,
        "scenario.seed",
        [">= 0", "got -1"],
        id="seed-negative",
    ),
    pytest.param(
        "[kitchen, hall, [1.0, 4.5]]",
        "[kitchen, garage, [1.0, 4.5]]",
        21,
        "scenario.people[0].route[1]",
        ["unknown region 'garage'"],
        id="route-unknown-region",
    ),
    pytest.param(
        "[kitchen, hall, [1.0, 4.5]]",
        "[kitchen, hall, [1.0, x]]",
        21,
        "scenario.people[0].route[2][1]",
        ["expected a valid number"],
        id="route-point-not-a-number",
    ),
    pytest.param(
        "- action: waypoint_search",
        "- {action: waypoint_search, condition: target_visible}",
        15,
        "behavior.tree.fallback.children[1]",
        ["exactly one of", "got 'action' and 'condition'"],
        id="tree-node-two-keys",
    ),
    pytest.param(
        "    fallback:\n",
        "    selector:\n",
        12,
        "behavior.tree.selector",
        ["unknown key", "sequence, fallback, parallel"],
        id="tree-unknown-composite",
    ),
    pytest.param(
        "- action: waypoint_search",
        "- action: WaypointSearch",
        15,
        "behavior.tree.fallback.children[1].action",
        ["snake_case"],
        id="tree-leaf-not-snake-case",
    ),
    pytest.param(
        "        - condition: target_visible\n        - action: waypoint_search\n",
        "        []\n",
        13,
        "behavior.tree.fallback.children",
        ["at least 1 item"],
        id="tree-no-children",
    ),
    pytest.param(
        "clothes: {upper: [200, 30, 40]",
        "clothes: {upper: [300, 30, 40]",
        20,
        "scenario.people[0].clothes.upper[0]",
        ["<= 255", "got 300"],
        id="colour-out-of-range",
    ),
    pytest.param(
        "{name: kitchen, polygon: [[0, 0], [4, 0], [4, 3], [0, 3]]}",
        "{name: kitchen}",
        4,
        "map.regions[0].polygon",
        ["required key is missing"],
        id="missing-required-key",
    ),
    pytest.param(
        "map:\n",
        "map:\n  resolution: 0.05\n  resolution: 0.1\n",
        4,
        "map.resolution",
        ["duplicate key (first on line 3)"],
        id="duplicate-key",
    ),
    pytest.param(
        "map:\n",
        "map:\n  sensor_model: {p_min: 0.9, p_max: 0.5}\n",
        3,
        "map.sensor_model.p_max",
        ["p_max > p_min"],
        id="sensor-model-bounds",
    ),
    pytest.param(
        "map:\n",
        "map:\n  occupancy: maps/nowhere.yaml\n",
        3,
        "map.occupancy",
        ["maps/nowhere.yaml does not exist"],
        id="occupancy-missing",
    ),
    pytest.param(
        "  doors:\n",
        "  obstacles:\n    - {name: table, polygon: [[0.5, 4], [1.5, 4], [1.5, 5], [0.5, 5]]}\n"
        "  doors:\n",
        23,
        "scenario.people[0].route[2]",
        ["expected a point outside the furniture, got (1, 4.5) inside obstacle 'table'"],
        id="route-point-in-furniture",
    ),
    pytest.param(
        "behavior:\n",
        "  obstacles:\n    - {name: table, polygon: [[1, 1], [2, 1], [2, 2], [1, 2]]}\n"
        "robot:\n  start: {x: 1.5, y: 1.5}\nbehavior:\n",
        13,
        "robot.start",
        ["expected a start clear of the furniture, got (1.5, 1.5)", "overlaps obstacle 'table'"],
        id="robot-start-in-furniture",
    ),
    pytest.param(
        "behavior:\n",
        "  obstacles:\n    - {polygon: [[1, 1], [2, 1], [2, 2], [1, 2]]}\n"
        "robot:\n  radius: 0.3\n  start: {x: 2.2, y: 1.5}\nbehavior:\n",
        14,
        "robot.start",
        ["the robot (radius 0.3 m) overlaps map.obstacles[0]"],
        id="robot-body-in-furniture",
    ),
    pytest.param(
        "map:\n",
        "map:\n  resolution: 0.0001\n",
        3,
        "map.resolution",
        ["map at 0.0001 m (", "cells) need about", "over the limit of 2 GiB"],
        id="grids-over-memory-limit",
    ),
    pytest.param(
        "behavior:\n",
        "prediction: {model: svm}\nbehavior:\n",
        10,
        "prediction.model",
        ["'svr', 'svr-time', 'poly3' or 'cv'", "got 'svm'"],
        id="prediction-model-unknown",
    ),
    pytest.param(
        "name: small\n",
        "name: small\nrobot: {radius: true, max_linear_speed: -1}\n",
        2,
        "robot.radius",
        ["number", "(+1 more)"],
        id="several-errors",
    ),
]


@pytest.mark.parametrize(("old", "new", "line", "path", "fragments"), BROKEN)
def test_broken_mission_is_one_error_line_with_exit_2(
    old: str,
    new: str,
    line: int,
    path: str,
    fragments: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    file = tmp_path / "bad.yaml"
    file.write_text(edit(old, new))
    code, out, err = run_cli(["mission", "validate", str(file)], capsys, monkeypatch)
    assert code == 2
    assert out == ""
    assert_one_error_line(err, f"pfctl: error: {file}:{line}: {path}: ", *fragments)


def test_yaml_syntax_error_names_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    file = tmp_path / "bad.yaml"
    file.write_text(edit("target: alice", "target: alice: bob"))
    code, _, err = run_cli(["mission", "validate", str(file)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(
        err, f"pfctl: error: {file}:17: YAML syntax error: ", "mapping values are not allowed"
    )


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        pytest.param(b"", "the file is empty", id="empty"),
        pytest.param(b"# only a comment\n", "the file is empty", id="only-comment"),
        pytest.param(b"- a\n- b\n", ":1: expected a mapping of mission sections", id="list"),
        pytest.param(b"name: caf\xe9\n", ":1: not UTF-8 text", id="latin-1"),
        pytest.param(b"name: a\n---\nname: b\n", ":2: YAML syntax error", id="two-documents"),
    ],
)
def test_unreadable_files_are_one_line(
    content: bytes,
    fragment: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    file = tmp_path / "bad.yaml"
    file.write_bytes(content)
    code, _, err = run_cli(["mission", "validate", str(file)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, f"pfctl: error: {file}", fragment)


def test_missing_file_and_directory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    missing = tmp_path / "nowhere.yaml"
    code, _, err = run_cli(["mission", "validate", str(missing)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, f"pfctl: error: {missing}: no such file")
    code, _, err = run_cli(["mission", "validate", str(tmp_path)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, f"pfctl: error: {tmp_path}: is a directory")


def test_validate_reports_every_file_and_fails_if_any_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(edit("target: alice", "target: carol"))
    code, out, err = run_cli(["mission", "validate", str(bad), str(HOUSE)], capsys, monkeypatch)
    assert code == 2
    assert out.startswith(f"OK {HOUSE}: ")
    assert_one_error_line(err, f"pfctl: error: {bad}:17: scenario.target: ")


def test_load_mission_raises_mission_error_for_users_and_loads_mission_names_source() -> None:
    with pytest.raises(MissionError, match=r"^inline:4: map\.regions\[0\]\.polygon: "):
        loads_mission(MINIMAL.replace("[0, 2]]", "[3, 0]]"), source="inline")


# --------------------------------------------------------------------------------------------
# the real console contract, in a subprocess
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_subprocess_contract_for_a_broken_and_a_missing_mission(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(edit("[kitchen, hall]", "[kitchen, garage]"))
    result = run_subprocess(["mission", "validate", str(bad)], cwd=tmp_path)
    assert result.returncode == 2
    assert result.stdout == ""
    assert_one_error_line(
        result.stderr,
        f"pfctl: error: {bad}:8: map.doors[0].between: unknown region 'garage'",
    )
    result = run_subprocess(["mission", "validate", "missing.yaml"], cwd=tmp_path)
    assert result.returncode == 2
    assert_one_error_line(result.stderr, "pfctl: error: missing.yaml: no such file")


@pytest.mark.slow
def test_subprocess_validates_the_shipped_mission() -> None:
    result = run_subprocess(["mission", "validate", "missions/house.yaml"], cwd=ROOT)
    assert result.returncode == 0, result.stderr
    assert result.stdout == (
        "OK missions/house.yaml: 5 regions, 5 doors, 6 obstacles, tree of 10 nodes\n"
    )


# --------------------------------------------------------------------------------------------
# the JSON Schema
# --------------------------------------------------------------------------------------------


def test_schema_command_prints_json_schema(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["mission", "schema"], capsys, monkeypatch)
    assert code == 0, err
    schema = json.loads(out)
    assert "map" in schema["properties"]
    assert set(schema["required"]) == {"name", "map"}
    assert schema["additionalProperties"] is False
    assert schema == dump_json_schema()
    assert schema == Mission.model_json_schema()


def test_schema_out_writes_the_file_atomically(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "mission.schema.json"
    out.write_text("old")
    code, _, err = run_cli(["mission", "schema", "--out", str(out)], capsys, monkeypatch)
    assert code == 0, err
    assert json.loads(out.read_text())["properties"]["map"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mission.schema.json"]

    nowhere = tmp_path / "no" / "dir" / "schema.json"
    code, _, err = run_cli(["mission", "schema", "--out", str(nowhere)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(err, f"pfctl: error: --out {nowhere}: no such folder {nowhere.parent}")
    assert not nowhere.parent.exists()


@pytest.mark.slow
def test_subprocess_schema_is_valid_json() -> None:
    result = run_subprocess(["mission", "schema"], cwd=ROOT)
    assert result.returncode == 0, result.stderr
    assert "map" in json.loads(result.stdout)["properties"]


# --------------------------------------------------------------------------------------------
# the occupancy map must be readable, and every grid of the map must fit the memory limit
# --------------------------------------------------------------------------------------------


def _with_occupancy(tmp_path: Path, image: bytes | None) -> tuple[Path, Path]:
    """MINIMAL with ``map.occupancy: maps/m.yaml`` (line 3) whose image is ``image`` (None: no
    image file); (mission, image path)."""
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n")
    if image is not None:
        (maps / "m.pgm").write_bytes(image)
    mission = tmp_path / "mission.yaml"
    mission.write_text(MINIMAL.replace("map:\n", "map:\n  occupancy: maps/m.yaml\n"))
    return mission, maps / "m.pgm"


@pytest.mark.parametrize(
    ("image", "fragment"),
    [
        pytest.param(None, "map image not found", id="no-image"),
        pytest.param(b"\x89PNG\r\n\x1a\n" + bytes(64), "unsupported image", id="png"),
        pytest.param(b"P5\nten ten\n255\n", "bad PGM header", id="bad-header"),
        pytest.param(
            b"P5\n10 10\n255\n" + bytes(50),
            "PGM pixel data truncated (50 bytes, 100 expected)",
            id="truncated",
        ),
    ],
)
def test_an_unreadable_occupancy_image_is_refused_by_validate(
    image: bytes | None,
    fragment: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    mission, pgm = _with_occupancy(tmp_path, image)
    code, out, err = run_cli(["mission", "validate", str(mission)], capsys, monkeypatch)
    assert code == 2 and out == ""
    assert_one_error_line(
        err, f"pfctl: error: {mission}:3: map.occupancy: unreadable map: {pgm}: {fragment}"
    )


def test_a_readable_occupancy_map_validates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    mission, _ = _with_occupancy(tmp_path, b"P5\n10 10\n255\n" + bytes([254]) * 100)
    code, out, err = run_cli(["mission", "validate", str(mission)], capsys, monkeypatch)
    assert code == 0 and out.startswith(f"OK {mission}"), err


def test_an_oversized_occupancy_image_is_refused_without_reading_its_pixels(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 30000 × 30000 PGM (a sparse file: 900 MB that take no disk) is refused from its
    header alone."""
    mission, pgm = _with_occupancy(tmp_path, b"P5\n30000 30000\n255\n")
    with pgm.open("r+b") as handle:
        handle.truncate(len(b"P5\n30000 30000\n255\n") + 30000 * 30000)
    code, _, err = run_cli(["mission", "validate", str(mission)], capsys, monkeypatch)
    assert code == 2
    assert_one_error_line(
        err,
        f"pfctl: error: {mission}:3: map.occupancy: {tmp_path / 'maps' / 'm.yaml'}: the grids of "
        "a 1500 × 1500 m map at 0.05 m (30000 × 30000 cells) need about",
        "over the limit of 2 GiB",
    )


HUGE = MINIMAL.replace(
    "[[0, 0], [3, 0], [3, 2], [0, 2]]", "[[0, 0], [1000, 0], [1000, 1000], [0, 1000]]"
)


@pytest.mark.parametrize(
    "args",
    [
        pytest.param(["mission", "validate"], id="validate"),
        pytest.param(["map", "export", "--out", "OUT/m.yaml"], id="map-export"),
        pytest.param(["map", "render", "--png", "OUT/m.png"], id="map-render"),
        pytest.param(["sim", "run", "--duration", "5", "--png", "OUT/s.png"], id="sim-run"),
        pytest.param(["sim", "export-map", "--out", "OUT/m.yaml"], id="sim-export-map"),
        pytest.param(["predict", "TRACK", "--model", "cv", "--mission"], id="predict"),
        pytest.param(["follow", "--duration", "5", "--out", "OUT"], id="follow"),
        pytest.param(["search", "--duration", "5", "--out", "OUT"], id="search"),
        pytest.param(["bench", "--episodes", "1", "--out", "OUT"], id="bench"),
    ],
)
def test_a_map_over_the_memory_limit_is_refused_by_every_command(
    args: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """1000 × 1000 m at 0.05 m: one line from the mission's validation, nothing written."""
    mission = tmp_path / "huge.yaml"
    mission.write_text(HUGE)
    track = tmp_path / "t.csv"
    track.write_text("t,x,y\n0,1,1\n0.1,1.1,1\n0.2,1.2,1\n")
    out = tmp_path / "out"
    words = [str(track) if a == "TRACK" else a.replace("OUT", str(out)) for a in args]
    full = [*words, str(mission)] if "TRACK" in args else [*words[:2], str(mission), *words[2:]]
    if args[0] in ("follow", "search", "bench"):
        full = [args[0], str(mission), *words[1:]]
    code, _, err = run_cli(full, capsys, monkeypatch)
    assert code == 2, err
    assert_one_error_line(
        err,
        f"pfctl: error: {mission}:2: map.resolution: the grids of a 1001 × 1001 m map at 0.05 m "
        "(20020 × 20020 cells) need about 149 GiB, over the limit of 2 GiB",
    )
    assert not out.exists()


def test_an_explicit_resolution_over_the_memory_limit_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    for command in (["map", "export"], ["sim", "export-map"], ["map", "render"]):
        option = "--png" if command[1] == "render" else "--out"
        out = tmp_path / ("m.png" if option == "--png" else "m.yaml")
        args = [*command, str(HOUSE), "--resolution", "0.0005", option, str(out)]
        code, _, err = run_cli(args, capsys, monkeypatch)
        assert code == 2
        assert_one_error_line(
            err, "pfctl: error: --resolution 0.0005: the grids of a 13 × 10 m map at 0.0005 m"
        )
        assert not out.exists()
