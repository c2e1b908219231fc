"""build_tree (real py_trees ticking) and the drawings of a layout (§II-A, Fig. 2).

The leaves here are tiny scripted behaviours standing for the real ones: each returns the status
the test sets for its name and records its ticks, starts and terminations.
"""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import Any

import pydot
import pytest
from PIL import Image
from py_trees.behaviour import Behaviour
from py_trees.common import Status

from pfctl.core.behavior.registry import LEAF_SPECS
from pfctl.core.behavior.tree import EpisodeTimeout, build_tree, parse_layout
from pfctl.mission import load_mission
from pfctl.mission.tree import paper_tree
from pfctl.plots.behavior_tree import ascii_tree, btcpp_xml, dot_tree, png_tree
from tests.conftest import HOUSE_MISSION

S, F, R, INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID


class Scripted(Behaviour):
    """A leaf whose status is ``world[name]``; it counts ticks and starts, logs terminations."""

    def __init__(self, name: str, world: dict[str, Status]) -> None:
        super().__init__(name=name)
        self.world = world
        self.ticks = 0
        self.starts = 0
        self.terminated: list[Status] = []

    def initialise(self) -> None:
        self.starts += 1

    def update(self) -> Status:
        self.ticks += 1
        return self.world[self.name]

    def terminate(self, new_status: Status) -> None:
        self.terminated.append(new_status)


class Harness:
    """A factory of scripted leaves, a fake clock and the leaves it made, by name."""

    def __init__(self, **statuses: Status) -> None:
        self.world: dict[str, Status] = dict(statuses)
        self.leaves: dict[str, Scripted] = {}
        self.calls: list[tuple[str, str, dict[str, Any]]] = []
        self.now = 0.0

    def factory(self, kind: str, name: str, params: dict[str, Any]) -> Behaviour:
        self.calls.append((kind, name, params))
        leaf = Scripted(name, self.world)
        self.leaves[name] = leaf
        return leaf

    def clock(self) -> float:
        return self.now

    def build(self, layout: dict[str, Any]) -> Behaviour:
        return build_tree(layout, self.factory, self.clock)


def tick(root: Behaviour, times: int = 1) -> Status:
    for _ in range(times):
        root.tick_once()
    return root.status


def paper_layout() -> dict[str, Any]:
    return paper_tree().model_dump(exclude_none=True)


def seq(*children: dict[str, Any], memory: bool = False) -> dict[str, Any]:
    return {"sequence": {"children": list(children), "memory": memory}}


def action(name: str, **params: Any) -> dict[str, Any]:
    return {"action": name, "params": params}


def condition(name: str, **params: Any) -> dict[str, Any]:
    return {"condition": name, "params": params}


#: A 26-node tree using every kind of node.
BIG: dict[str, Any] = {
    "fallback": {
        "name": "root",
        "children": [
            {
                "sequence": {
                    "name": "follow",
                    "children": [
                        condition("target_visible", max_age=0.3),
                        {
                            "parallel": {
                                "name": "follow_and_gaze",
                                "policy": "success_on_one",
                                "children": [
                                    action("follow_target", distance=1.2),
                                    action("gaze_at_target"),
                                ],
                            }
                        },
                    ],
                }
            },
            {
                "sequence": {
                    "name": "reacquire",
                    "memory": True,
                    "children": [
                        condition("target_tracked"),
                        {"timeout": {"seconds": 5, "child": action("go_to_last_seen")}},
                    ],
                }
            },
            {
                "fallback": {
                    "name": "find",
                    "memory": True,
                    "children": [
                        {
                            "sequence": {
                                "name": "predict_and_look",
                                "children": [
                                    condition("prediction_available"),
                                    {
                                        "retry": {
                                            "attempts": 3,
                                            "child": action("go_to_prediction", tolerance=0.6),
                                        }
                                    },
                                    action("look_around", seconds=6),
                                ],
                            }
                        },
                        seq(
                            {"inverter": {"child": condition("near_target")}},
                            {
                                "repeat": {
                                    "name": "sweep_twice",
                                    "count": 2,
                                    "child": action("look_around"),
                                }
                            },
                        ),
                        {"force_success": {"child": action("waypoint_search")}},
                    ],
                }
            },
            {"force_failure": {"child": condition("target_lost_for", seconds=30)}},
            action("stop"),
        ],
    }
}


# --------------------------------------------------------------------------------------------
# the paper's tree (Fig. 2)


def test_paper_tree_from_the_house_mission_resolves_every_leaf() -> None:
    layout = load_mission(HOUSE_MISSION).behavior.tree.model_dump(exclude_none=True)
    h = Harness()
    root = h.build(layout)
    assert root.name == "root"
    assert [c.name for c in root.children] == ["follow", "find"]
    calls = {name: (kind, params) for kind, name, params in h.calls}
    assert calls["target_visible"] == ("condition", {"max_age": 0.5})
    assert calls["follow_target"] == ("action", {"distance": None})  # the mission's value
    assert calls["look_around"] == (
        "action",
        {"seconds": 8.0, "pan": 1.4, "turn": True, "until_looked": True, "min_seconds": 1.0},
    )
    assert [name for _, name, _ in h.calls] == [
        "target_visible",
        "follow_target",
        "prediction_available",
        "go_to_prediction",
        "look_around",
        "waypoint_search",
    ]


def test_paper_tree_follows_while_the_target_is_visible() -> None:
    h = Harness(target_visible=S, follow_target=R)
    root = h.build(paper_layout())
    assert tick(root) == R
    assert root.tip() is h.leaves["follow_target"]
    assert h.leaves["waypoint_search"].ticks == 0


def test_paper_tree_goes_to_the_prediction_when_the_target_is_lost() -> None:
    h = Harness(target_visible=F, prediction_available=S, go_to_prediction=R)
    root = h.build(paper_layout())
    assert tick(root) == R
    assert root.tip() is h.leaves["go_to_prediction"]
    # at the prediction: look around
    h.world["go_to_prediction"] = S
    h.world["look_around"] = R
    assert tick(root) == R
    assert root.tip() is h.leaves["look_around"]


def test_paper_tree_searches_way_points_when_the_prediction_fails() -> None:
    h = Harness(target_visible=F, prediction_available=F, waypoint_search=R)
    root = h.build(paper_layout())
    assert tick(root) == R
    assert root.tip() is h.leaves["waypoint_search"]
    # looking around without finding the target also falls through to the way-point search
    h.world.update(prediction_available=S, go_to_prediction=S, look_around=F)
    assert tick(root) == R
    assert root.tip() is h.leaves["waypoint_search"]
    h.world["waypoint_search"] = F  # nothing left to search
    assert tick(root) == F


def test_reactive_tree_rechecks_the_condition_and_stops_the_preempted_action() -> None:
    h = Harness(target_visible=F, prediction_available=F, waypoint_search=R, follow_target=R)
    root = h.build(paper_layout())
    tick(root, 3)
    search = h.leaves["waypoint_search"]
    assert search.status == R and search.ticks == 3 and search.starts == 1
    assert h.leaves["target_visible"].ticks == 3  # re-checked on every tick
    h.world["target_visible"] = S  # seen again: the higher-priority branch takes over
    assert tick(root) == R
    assert root.tip() is h.leaves["follow_target"]
    assert search.terminated == [INVALID] and search.status == INVALID
    tick(root, 2)
    assert h.leaves["target_visible"].ticks == 6
    h.world["target_visible"] = F  # lost while following: the follow action is stopped too
    tick(root)
    assert h.leaves["follow_target"].terminated == [INVALID]
    assert root.tip() is search and search.starts == 2


def test_a_sequence_with_memory_resumes_at_the_running_child() -> None:
    h = Harness(target_visible=S, follow_target=R)
    root = h.build(seq(condition("target_visible"), action("follow_target"), memory=True))
    tick(root, 3)
    assert h.leaves["target_visible"].ticks == 1
    assert h.leaves["follow_target"].ticks == 3
    h = Harness(target_visible=S, follow_target=R)
    root = h.build(seq(condition("target_visible"), action("follow_target")))
    tick(root, 3)
    assert h.leaves["target_visible"].ticks == 3


def test_a_fallback_with_memory_keeps_ticking_the_running_child() -> None:
    layout = {
        "fallback": {
            "memory": True,
            "children": [condition("target_visible"), action("waypoint_search")],
        }
    }
    h = Harness(target_visible=F, waypoint_search=R)
    root = h.build(layout)
    tick(root)
    h.world["target_visible"] = S  # not looked at again while the search runs
    assert tick(root, 2) == R
    assert h.leaves["target_visible"].ticks == 1
    assert h.leaves["waypoint_search"].ticks == 3


# --------------------------------------------------------------------------------------------
# decorators and parallels


def test_timeout_fails_a_long_running_child_on_the_given_clock() -> None:
    h = Harness(look_around=R)
    root = h.build({"timeout": {"seconds": 2.0, "child": action("look_around")}})
    assert isinstance(root, EpisodeTimeout) and root.name == "timeout 2 s"
    leaf = h.leaves["look_around"]
    assert tick(root) == R  # t = 0: started
    h.now = 1.9
    assert tick(root) == R and leaf.terminated == []
    h.now = 2.0
    assert tick(root) == F
    assert leaf.terminated == [INVALID] and leaf.status == INVALID  # stopped: cancels its goal
    h.now = 2.5  # the next tick starts it afresh with a new deadline
    assert tick(root) == R and leaf.starts == 2
    h.now = 4.4
    assert tick(root) == R
    h.world["look_around"] = S  # finished in time: passes through
    assert tick(root) == S and leaf.terminated == [INVALID, S]


def test_timeout_ignores_the_wall_clock() -> None:
    h = Harness(look_around=R)
    root = h.build({"timeout": {"seconds": 0.001, "child": action("look_around")}})
    tick(root)
    import time

    time.sleep(0.01)
    assert tick(root) == R  # the fake clock has not moved


def test_retry_runs_the_child_at_most_attempts_times_in_all() -> None:
    h = Harness(go_to_prediction=F)
    root = h.build({"retry": {"attempts": 3, "child": action("go_to_prediction")}})
    assert root.name == "retry ×3"
    assert [tick(root) for _ in range(3)] == [R, R, F]
    assert h.leaves["go_to_prediction"].starts == 3
    # a success on the second attempt ends it
    h = Harness(go_to_prediction=F)
    root = h.build({"retry": {"attempts": 3, "child": action("go_to_prediction")}})
    assert tick(root) == R
    h.world["go_to_prediction"] = S
    assert tick(root) == S and h.leaves["go_to_prediction"].starts == 2
    # attempts: 1 is a single run
    h = Harness(go_to_prediction=F)
    root = h.build({"retry": {"attempts": 1, "child": action("go_to_prediction")}})
    assert tick(root) == F


def test_repeat_runs_the_child_count_times_while_it_succeeds() -> None:
    h = Harness(look_around=S)
    root = h.build({"repeat": {"count": 3, "child": action("look_around")}})
    assert [tick(root) for _ in range(3)] == [R, R, S]
    assert h.leaves["look_around"].starts == 3
    h = Harness(look_around=S)
    root = h.build({"repeat": {"count": 3, "child": action("look_around")}})
    assert tick(root) == R
    h.world["look_around"] = F
    assert tick(root) == F and h.leaves["look_around"].starts == 2


@pytest.mark.parametrize(
    ("kind", "child", "expected"),
    [
        ("force_success", F, S),
        ("force_success", S, S),
        ("force_success", R, R),
        ("force_failure", S, F),
        ("force_failure", F, F),
        ("force_failure", R, R),
        ("inverter", S, F),
        ("inverter", F, S),
        ("inverter", R, R),
    ],
)
def test_status_decorators(kind: str, child: Status, expected: Status) -> None:
    h = Harness(stop=child)
    root = h.build({kind: {"child": action("stop")}})
    assert root.name == kind
    assert tick(root) == expected


def _parallel(policy: str) -> dict[str, Any]:
    return {
        "parallel": {
            "name": "both",
            "policy": policy,
            "children": [action("follow_target"), action("gaze_at_target")],
        }
    }


def test_parallel_success_on_all() -> None:
    h = Harness(follow_target=S, gaze_at_target=R)
    root = h.build(_parallel("success_on_all"))
    assert tick(root) == R
    h.world["gaze_at_target"] = S
    assert tick(root) == S
    assert h.leaves["follow_target"].ticks == 1  # a finished child is not ticked again
    h = Harness(follow_target=R, gaze_at_target=F)
    root = h.build(_parallel("success_on_all"))
    assert tick(root) == F
    assert h.leaves["follow_target"].terminated == [INVALID]


def test_parallel_success_on_one() -> None:
    h = Harness(follow_target=R, gaze_at_target=R)
    root = h.build(_parallel("success_on_one"))
    assert tick(root) == R
    h.world["gaze_at_target"] = S
    assert tick(root) == S
    assert h.leaves["follow_target"].terminated == [INVALID]  # the other one is stopped
    h = Harness(follow_target=S, gaze_at_target=F)
    assert tick(h.build(_parallel("success_on_one"))) == F  # any failure fails it


def test_the_big_tree_builds_with_readable_names() -> None:
    h = Harness()
    root = h.build(BIG)
    names = [b.name for b in root.iterate()]
    assert len(names) == 26
    for name in ("root", "follow_and_gaze", "reacquire", "timeout 5 s", "retry ×3", "inverter"):
        assert name in names
    assert "sweep_twice" in names and "sequence" in names


# --------------------------------------------------------------------------------------------
# errors name the place in the tree


def test_unknown_leaf_names_its_path() -> None:
    layout = paper_layout()
    find = layout["fallback"]["children"][1]["fallback"]
    plan = find["children"][0]["sequence"]
    plan["children"] = [condition("foo"), *plan["children"][1:]]
    with pytest.raises(ValueError) as err:
        build_tree(layout, Harness().factory, lambda: 0.0)
    message = str(err.value)
    assert message.startswith(
        "behavior.tree.fallback.children[1].fallback.children[0].sequence.children[0]: "
        "unknown condition 'foo' (known: target_visible, "
    )
    assert "\n" not in message
    with pytest.raises(ValueError, match=r"^behavior\.tree: unknown action 'target_visible'"):
        build_tree(action("target_visible"), Harness().factory, lambda: 0.0)


@pytest.mark.parametrize(
    ("layout", "message"),
    [
        (
            seq(condition("target_visible", max_age=-1)),
            "behavior.tree.sequence.children[0].params.max_age: expected at least 0, got -1",
        ),
        (
            seq(condition("target_visible", max_age="soon")),
            "behavior.tree.sequence.children[0].params.max_age: expected a number, got 'soon'",
        ),
        (
            seq(action("stop", fast=True)),
            "behavior.tree.sequence.children[0].params.fast: unknown parameter of stop",
        ),
        (
            seq(condition("target_lost_for")),
            "behavior.tree.sequence.children[0].params.seconds: required parameter",
        ),
        (
            {"sequence": {"children": []}},
            "behavior.tree.sequence.children: expected a non-empty list",
        ),
        ({"retry": {"child": action("stop")}}, "behavior.tree.retry.attempts: required key"),
        (
            {"retry": {"attempts": 0, "child": action("stop")}},
            "behavior.tree.retry.attempts: expected a whole number >= 1, got 0",
        ),
        (
            {"timeout": {"seconds": -2, "child": action("stop")}},
            "behavior.tree.timeout.seconds: expected a finite number > 0, got -2",
        ),
        (
            {"parallel": {"policy": "most", "children": [action("stop")]}},
            "behavior.tree.parallel.policy: expected one of success_on_all, success_on_one",
        ),
        (
            {"sequence": {"children": [action("stop")]}, "action": "stop"},
            "behavior.tree: expected exactly one of sequence, fallback, parallel",
        ),
        (
            {"sequence": {"children": [action("stop")], "memory": "yes"}},
            "behavior.tree.sequence.memory: expected true or false, got 'yes'",
        ),
        (
            {"inverter": {"child": action("stop"), "count": 2}},
            "behavior.tree.inverter.count: unknown key (expected one of: name, child)",
        ),
        ({"seq": {}}, "behavior.tree.seq: unknown key"),
    ],
)
def test_bad_layouts_raise_value_errors_naming_the_path(
    layout: dict[str, Any], message: str
) -> None:
    with pytest.raises(ValueError, match="^" + re.escape(message)):
        build_tree(layout, Harness().factory, lambda: 0.0)


def test_a_factory_value_error_gets_the_path() -> None:
    def factory(kind: str, name: str, params: dict[str, Any]) -> Behaviour:
        raise ValueError("no such skill")

    with pytest.raises(ValueError, match=r"^behavior\.tree\.sequence\.children\[0\]: no such"):
        build_tree(seq(action("stop")), factory, lambda: 0.0)


# --------------------------------------------------------------------------------------------
# drawings


LAYOUTS: dict[str, Callable[[], dict[str, Any]]] = {"paper": paper_layout, "big": lambda: BIG}


@pytest.mark.parametrize("which", sorted(LAYOUTS))
def test_ascii_has_every_node(which: str) -> None:
    layout = LAYOUTS[which]()
    text = ascii_tree(layout)
    nodes = parse_layout(layout).walk()
    lines = text.splitlines()
    assert len(lines) == len(nodes)
    for node, line in zip(nodes, lines, strict=True):
        assert node.label in line
    if which == "paper":
        assert lines[0] == "[?] root (fallback)"
        assert "(target_visible) max_age=0.5" in text
        assert "[follow_target] distance=(mission)" in text
        assert "[look_around] seconds=8 pan=1.4 turn=true" in text
        assert "    ├── [→] predict_and_look (sequence)" in text


@pytest.mark.parametrize("which", sorted(LAYOUTS))
def test_dot_parses_with_one_node_per_tree_node(which: str) -> None:
    layout = LAYOUTS[which]()
    size = len(parse_layout(layout).walk())
    (graph,) = pydot.graph_from_dot_data(dot_tree(layout))
    nodes = [n for n in graph.get_nodes() if n.get_name() not in ("graph", "node", "edge")]
    assert len(nodes) == size
    assert len(graph.get_edges()) == size - 1
    shapes = {n.get_name(): str(n.get("shape")).strip('"') for n in nodes}
    kinds = [n.kind for n in parse_layout(layout).walk()]
    for i, kind in enumerate(kinds):
        expected = {"condition": "ellipse", "action": "box"}.get(kind)
        assert expected is None or shapes[f"n{i}"] == expected
    labels = " ".join(str(n.get("label")) for n in nodes)
    assert "target_visible" in labels and "→" in labels


@pytest.mark.parametrize("which", sorted(LAYOUTS))
def test_png_is_a_real_picture(which: str) -> None:
    data = png_tree(LAYOUTS[which](), title="a tree")
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    with Image.open(io.BytesIO(data)) as image:
        width, height = image.size
    assert 500 <= width <= 4000 and 250 <= height <= 1500
    assert width > height


def test_btcpp_xml_is_v4_with_every_leaf_modelled() -> None:
    text = btcpp_xml(BIG)
    root = ET.fromstring(text)
    assert root.tag == "root"
    assert root.get("BTCPP_format") == "4" and root.get("main_tree_to_execute") == "MainTree"
    (tree,) = root.findall("BehaviorTree")
    assert tree.get("ID") == "MainTree" and len(tree) == 1
    model = root.find("TreeNodesModel")
    assert model is not None
    declared = {e.get("ID"): e.tag for e in model}
    assert declared == {
        name: spec.kind.capitalize() for name, spec in LEAF_SPECS.items()
    }  # Condition / Action
    leaves = [e for e in tree.iter() if e.tag in LEAF_SPECS]
    assert len(leaves) == sum(1 for n in parse_layout(BIG).walk() if n.is_leaf)
    # the mapping of composites and decorators
    top = tree[0]
    assert top.tag == "ReactiveFallback" and top.get("name") == "root"
    tags = [e.tag for e in tree.iter()]
    for tag in ("ReactiveSequence", "Sequence", "Fallback", "Parallel", "Inverter"):
        assert tag in tags
    assert tree.find(".//Parallel").attrib == {  # type: ignore[union-attr]
        "name": "follow_and_gaze",
        "success_count": "1",
        "failure_count": "1",
    }
    assert tree.find(".//RetryUntilSuccessful").get("num_attempts") == "3"  # type: ignore[union-attr]
    assert tree.find(".//Timeout").get("msec") == "5000"  # type: ignore[union-attr]
    repeat = tree.find(".//Repeat")
    assert repeat is not None and repeat.attrib == {"name": "sweep_twice", "num_cycles": "2"}
    assert tree.find(".//ForceSuccess/waypoint_search") is not None
    assert tree.find(".//ForceFailure/target_lost_for").get("seconds") == "30"  # type: ignore[union-attr]
    assert tree.find(".//target_visible").attrib == {"max_age": "0.3"}  # type: ignore[union-attr]
    # ports: defaults where the registry has one, none for "the mission's value"
    look = model.find("Action[@ID='look_around']")
    assert look is not None
    ports = {p.get("name"): p.attrib for p in look.findall("input_port")}
    assert ports["turn"] == {"name": "turn", "type": "bool", "default": "true"}
    assert ports["pan"]["default"] == "1.4"
    follow = model.find("Action[@ID='follow_target']/input_port[@name='distance']")
    assert follow is not None and "default" not in follow.attrib and follow.text
    description = model.find("Condition[@ID='target_visible']/MetadataFields/Metadata")
    assert description is not None and "max_age" in description.get("description", "")


def test_btcpp_paper_tree_is_reactive() -> None:
    tree = ET.fromstring(btcpp_xml(paper_layout())).find("BehaviorTree")
    assert tree is not None
    assert [e.tag for e in tree.iter()][1:4] == [
        "ReactiveFallback",
        "ReactiveSequence",
        "target_visible",
    ]
    follow = tree.find(".//follow_target")
    assert follow is not None and follow.attrib == {}  # distance: the mission's value
