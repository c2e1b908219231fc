"""Mission inheritance (``extends:``) and tree files (``behavior.tree: {include: ...}``): the
merge semantics, paths relative to each file, errors that name the file and line the bad value
came from, cycles and missing files as one line with exit status 2; and every shipped mission
and tree file loads."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from pfctl.errors import MissionError
from pfctl.mission import Mission, TreeNode, load_mission, loads_mission, merge_mission_data
from tests.conftest import run_cli

ROOT = Path(__file__).resolve().parents[2]
MISSIONS = ROOT / "missions"
HOUSE = MISSIONS / "house.yaml"

BASE = """\
name: base
description: the base mission
map:
  resolution: 0.1
  regions:
    - {name: kitchen, polygon: [[0, 0], [4, 0], [4, 3], [0, 3]]}
    - {name: hall, polygon: [[4, 0], [6, 0], [6, 3], [4, 3]]}
  doors:
    - {between: [kitchen, hall], segment: [[4, 1], [4, 2]]}
robot:
  max_linear_speed: 0.3
  start: {x: 1.0, y: 1.0}
search:
  alpha: 0.1
scenario:
  target: alice
  people:
    - name: alice
      clothes: {upper: [200, 30, 40], lower: [40, 40, 120]}
      route: [kitchen, hall]
"""

REACTIVE = """\
fallback:
  name: root
  children:
    - sequence:
        name: follow
        children:
          - condition: target_visible
          - action: follow_target
    - action: stop
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def validate(
    path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> tuple[int, str, str]:
    return run_cli(["mission", "validate", str(path)], capsys, monkeypatch)


def one_line(err: str) -> str:
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    return lines[0]


# --------------------------------------------------------------------------------------------
# merge semantics
# --------------------------------------------------------------------------------------------


def test_merge_mappings_key_by_key_lists_and_scalars_replace_trees_whole() -> None:
    base = {
        "a": {"x": 1, "y": {"p": 1, "q": 2}},
        "l": [1, 2, 3],
        "s": "base",
        "behavior": {"tick_hz": 5, "tree": {"fallback": {"name": "b", "memory": True}}},
    }
    child = {
        "a": {"y": {"q": 3}, "z": 4},
        "l": [9],
        "s": None,
        "behavior": {"tree": {"fallback": {"name": "c"}}},
    }
    assert merge_mission_data(base, child) == {
        "a": {"x": 1, "y": {"p": 1, "q": 3}, "z": 4},
        "l": [9],
        "s": None,
        "behavior": {"tick_hz": 5, "tree": {"fallback": {"name": "c"}}},
    }
    assert base["a"] == {"x": 1, "y": {"p": 1, "q": 2}}  # the inputs are not changed


def test_a_child_overrides_what_it_names_and_keeps_the_rest(tmp_path: Path) -> None:
    write(tmp_path / "base.yaml", BASE)
    child = write(
        tmp_path / "child.yaml",
        "extends: base.yaml\n"
        "name: child\n"
        "robot: {max_linear_speed: 0.2}\n"  # a mapping merges: start stays
        "map: {resolution: 0.05}\n"  # regions and doors stay
        "scenario:\n"
        "  people:\n"  # a list replaces
        "    - name: alice\n"
        "      clothes: {upper: [1, 2, 3], lower: [4, 5, 6]}\n"
        "      route: [hall]\n",
    )
    mission = load_mission(child)
    base = load_mission(tmp_path / "base.yaml")
    assert mission.name == "child" and mission.description == "the base mission"
    assert mission.robot.max_linear_speed == 0.2 and mission.robot.start == base.robot.start
    assert mission.map.resolution == 0.05 and mission.map.regions == base.map.regions
    assert len(mission.scenario.people) == 1 and mission.scenario.people[0].route == ("hall",)
    assert mission.scenario.target == "alice" and mission.search.alpha == 0.1
    # exactly the mission one would get by writing the merged file out
    merged = merge_mission_data(yaml.safe_load(BASE), yaml.safe_load(child.read_text()))
    del merged["extends"]
    assert mission == Mission.model_validate(merged)


def test_extends_chains_and_paths_are_relative_to_each_file(tmp_path: Path) -> None:
    write(tmp_path / "maps" / "base.yaml", BASE.replace("name: base", "name: grandparent"))
    write(tmp_path / "trees" / "reactive.yaml", REACTIVE)
    write(
        tmp_path / "middle" / "parent.yaml",
        "extends: ../maps/base.yaml\nname: parent\nbehavior:\n"
        "  tree: {include: ../trees/reactive.yaml}\n",
    )
    child = write(
        tmp_path / "deep" / "er" / "child.yaml",
        "extends: ../../middle/parent.yaml\nsearch: {alpha: 0.2}\n",
    )
    mission = load_mission(child)
    assert mission.name == "parent" and mission.search.alpha == 0.2
    assert [n.label for n in mission.behavior.tree.walk() if n.is_leaf] == [
        "target_visible",
        "follow_target",
        "stop",
    ]
    # loads_mission resolves extends against base_dir
    again = loads_mission(child.read_text(), source="inline", base_dir=child.parent)
    assert again == mission


#: A readable 4 × 4 map image (the mission checks ``map.occupancy``'s image).
PGM = b"P5\n4 4\n255\n" + bytes([254]) * 16


def test_a_base_file_field_stays_relative_to_the_base(tmp_path: Path) -> None:
    occupancy = write(tmp_path / "maps" / "house_map.yaml", "image: x.pgm\nresolution: 0.1\n")
    (tmp_path / "maps" / "x.pgm").write_bytes(PGM)
    write(
        tmp_path / "base.yaml",
        BASE.replace(
            "  resolution: 0.1\n", "  resolution: 0.1\n  occupancy: maps/house_map.yaml\n"
        ),
    )
    child = write(tmp_path / "sub" / "child.yaml", "extends: ../base.yaml\nname: child\n")
    assert load_mission(child).map.occupancy == occupancy.resolve()
    # a child's own relative path is relative to the child
    write(tmp_path / "sub" / "own.yaml", "image: y.pgm\nresolution: 0.1\n")
    (tmp_path / "sub" / "y.pgm").write_bytes(PGM)
    own = write(
        tmp_path / "sub" / "own_child.yaml",
        "extends: ../base.yaml\nname: own\nmap: {occupancy: own.yaml}\n",
    )
    assert load_mission(own).map.occupancy == (tmp_path / "sub" / "own.yaml").resolve()


def test_a_tree_file_holds_what_behavior_tree_holds(tmp_path: Path) -> None:
    tree = write(tmp_path / "trees" / "reactive.yaml", REACTIVE)
    included = write(
        tmp_path / "m.yaml",
        BASE + "behavior:\n  tick_hz: 5\n  tree: {include: trees/reactive.yaml}\n",
    )
    inline = write(
        tmp_path / "inline.yaml",
        BASE
        + "behavior:\n  tick_hz: 5\n  tree:\n"
        + "".join(f"    {line}\n" for line in REACTIVE.splitlines()),
    )
    assert load_mission(included) == load_mission(inline)
    assert load_mission(included).behavior.tick_hz == 5
    assert load_mission(included).behavior.tree == TreeNode.model_validate(
        yaml.safe_load(tree.read_text())
    )


# --------------------------------------------------------------------------------------------
# errors: one line, the right file and line, exit 2
# --------------------------------------------------------------------------------------------


def test_an_error_in_the_base_names_the_base_and_one_in_the_child_names_the_child(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    base = write(
        tmp_path / "base.yaml", BASE.replace("route: [kitchen, hall]", "route: [kitchen, garage]")
    )
    child = write(tmp_path / "sub" / "child.yaml", "extends: ../base.yaml\nname: child\n")
    code, out, err = validate(child, capsys, monkeypatch)
    assert code == 2 and out == ""
    line = one_line(err)
    assert line.startswith(f"pfctl: error: {base}:20: "), line
    assert "scenario.people[0].route[1]: unknown region 'garage'" in line
    assert base.read_text().splitlines()[19].strip() == "route: [kitchen, garage]"

    write(tmp_path / "base.yaml", BASE)
    write(child, "extends: ../base.yaml\nname: child\nrobot:\n  max_linear_speed: -1\n")
    code, _, err = validate(child, capsys, monkeypatch)
    assert code == 2
    assert one_line(err).startswith(f"pfctl: error: {child}:4: robot.max_linear_speed: ")


def test_a_semantic_error_of_merged_values_points_at_the_value_that_broke_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    write(tmp_path / "base.yaml", BASE)
    # the child moves the start out of the house: the start (child, line 3) is the culprit
    child = write(
        tmp_path / "child.yaml", "extends: base.yaml\nrobot:\n  start: {x: 50.0, y: 1.0}\n"
    )
    code, _, err = validate(child, capsys, monkeypatch)
    assert code == 2
    assert one_line(err).startswith(f"pfctl: error: {child}:3: robot.start: expected a start")


def test_an_error_in_a_tree_file_names_the_tree_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    tree = write(tmp_path / "trees" / "bad.yaml", REACTIVE.replace("action: stop", "action: dance"))
    mission = write(tmp_path / "m.yaml", BASE + "behavior:\n  tree: {include: trees/bad.yaml}\n")
    code, _, err = validate(mission, capsys, monkeypatch)
    assert code == 2
    line = one_line(err)
    assert line.startswith(f"pfctl: error: {tree}:9: behavior.tree.fallback.children[1]"), line
    assert "unknown action 'dance'" in line


@pytest.mark.parametrize(
    ("child", "line", "fragment"),
    [
        pytest.param(
            "name: c\nextends: missing.yaml\n",
            2,
            "extends: expected an existing mission file, but {dir}/missing.yaml does not exist",
            id="missing-base",
        ),
        pytest.param(
            "extends: trees\n", 1, "extends: expected an existing mission file", id="directory"
        ),
        pytest.param("extends: [a.yaml]\n", 1, "extends: expected the path", id="not-a-string"),
        pytest.param(
            "extends: base.yaml\nbehavior:\n  tree: {include: trees/none.yaml}\n",
            3,
            "behavior.tree.include: expected an existing tree file, but {dir}/trees/none.yaml",
            id="missing-tree",
        ),
        pytest.param(
            "extends: base.yaml\nbehavior:\n  tree:\n    include: trees/r.yaml\n    memory: true\n",
            4,
            "behavior.tree.include: a tree read from a file takes no other keys",
            id="include-and-more",
        ),
        pytest.param(
            "extends: base.yaml\nname: a\nname: b\n", 3, "name: duplicate key", id="duplicate"
        ),
    ],
)
def test_bad_extends_and_include_are_one_line(
    child: str,
    line: int,
    fragment: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    write(tmp_path / "base.yaml", BASE)
    write(tmp_path / "trees" / "r.yaml", REACTIVE)
    file = write(tmp_path / "child.yaml", child)
    code, out, err = validate(file, capsys, monkeypatch)
    assert code == 2 and out == ""
    text = one_line(err)
    assert text.startswith(f"pfctl: error: {file}:{line}: "), text
    assert fragment.format(dir=tmp_path) in text, text


def test_a_cycle_is_one_line_naming_the_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    a = write(tmp_path / "a.yaml", "extends: sub/b.yaml\nname: a\n")
    write(tmp_path / "sub" / "b.yaml", "name: b\nextends: ../a.yaml\n")
    code, _, err = validate(a, capsys, monkeypatch)
    assert code == 2
    b = tmp_path / "sub" / "b.yaml"
    assert one_line(err) == (
        f"pfctl: error: {b}:2: extends: a mission cannot extend itself: {a} -> {b} -> {a}"
    )
    itself = write(tmp_path / "self.yaml", "extends: self.yaml\n")
    with pytest.raises(
        MissionError, match=r"self\.yaml:1: extends: a mission cannot extend itself"
    ):
        load_mission(itself)


def test_a_broken_base_file_names_the_base(tmp_path: Path) -> None:
    write(tmp_path / "base.yaml", "name: [unclosed\n")
    write(tmp_path / "empty.yaml", "# nothing\n")
    with pytest.raises(MissionError, match=r"base\.yaml:2: YAML syntax error"):
        load_mission(write(tmp_path / "c1.yaml", "extends: base.yaml\n"))
    with pytest.raises(MissionError, match=r"empty\.yaml: the file is empty"):
        load_mission(write(tmp_path / "c2.yaml", "extends: empty.yaml\n"))


# --------------------------------------------------------------------------------------------
# the shipped missions and trees
# --------------------------------------------------------------------------------------------

SHIPPED = sorted([*MISSIONS.glob("*.yaml"), *(MISSIONS / "baselines").glob("*.yaml")])


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(MISSIONS)))
def test_every_shipped_mission_validates(path: Path) -> None:
    mission = load_mission(path)
    assert mission.behavior.tree.size() >= 3


def test_mission_validate_accepts_them_all(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["mission", "validate", *map(str, SHIPPED)], capsys, monkeypatch)
    assert code == 0, err
    assert len(out.splitlines()) == len(SHIPPED)


@pytest.mark.parametrize(
    "path", sorted((MISSIONS / "baselines").glob("*.yaml")), ids=lambda p: p.stem
)
def test_bt_show_draws_every_baseline(
    path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code, out, err = run_cli(["bt", "show", str(path), "--format", "ascii"], capsys, monkeypatch)
    assert code == 0, err
    assert out.startswith("[?] root (fallback)") and "follow_target" in out


def test_the_paper_tree_file_is_the_house_tree_and_the_default() -> None:
    paper = yaml.safe_load((MISSIONS / "trees" / "paper.yaml").read_text())
    house = load_mission(HOUSE)
    assert house.behavior.tree == TreeNode.model_validate(paper)
    minimal = loads_mission(BASE)  # no behavior section: the default tree
    assert minimal.behavior.tree == house.behavior.tree


@pytest.mark.parametrize(
    ("ablation", "tree"),
    [("house_no_prediction", "no_prediction"), ("house_no_waypoint_search", "no_waypoint_search")],
)
def test_the_ablations_are_the_house_with_another_tree(ablation: str, tree: str) -> None:
    """They were full copies of house.yaml before ``extends``; the same missions now."""
    mission = load_mission(MISSIONS / f"{ablation}.yaml")
    house = load_mission(HOUSE)
    layout = yaml.safe_load((MISSIONS / "trees" / f"{tree}.yaml").read_text())
    behavior = house.behavior.model_copy(update={"tree": TreeNode.model_validate(layout)})
    expected = house.model_copy(
        update={"name": f"ahg-{ablation.replace('_', '-')}", "behavior": behavior}
    )
    assert mission == expected
