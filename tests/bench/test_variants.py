"""pfctl bench --vary: parsing, the cross product and its names, overrides before validation,
and one-line errors (exit 2, nothing written)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from pfctl.bench.plan import load_variant, mission_digest
from pfctl.bench.variants import (
    BASE,
    Variant,
    apply_overrides,
    parse_vary,
    split_values,
    variants,
)
from pfctl.errors import UserError
from tests.conftest import HOUSE_MISSION, run_cli


def test_values_are_yaml_and_commas_inside_brackets_stay() -> None:
    assert split_values("1, [1, 2], {a: 1, b: 2}, 'x,y'") == [
        "1",
        "[1, 2]",
        "{a: 1, b: 2}",
        "'x,y'",
    ]
    vary = parse_vary("control.following_band=[0.5, 2.5],[0.4,3]")
    assert vary.key == "control.following_band"
    assert vary.values == ([0.5, 2.5], [0.4, 3])
    assert vary.labels == ("[0.5, 2.5]", "[0.4,3]")
    vary = parse_vary("search.alpha=1, 2.5,true,null")
    assert vary.values == (1, 2.5, True, None) and vary.labels == ("1", "2.5", "true", "null")


def test_at_file_reads_a_yaml_value_named_by_its_stem(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "trees").mkdir()
    tree = {"fallback": {"children": [{"action": "follow_target"}, {"action": "look_around"}]}}
    (tmp_path / "trees" / "tiny.yaml").write_text(yaml.safe_dump(tree))
    vary = parse_vary("behavior.tree=@trees/tiny.yaml")
    assert vary.values == (tree,) and vary.labels == ("tiny",)


def test_cross_product_and_names() -> None:
    combos = variants([parse_vary("search.alpha=1,2"), parse_vary("search.beta=0.5,1,2")])
    assert [v.name for v in combos] == [
        f"search.alpha={a} search.beta={b}" for a in (1, 2) for b in (0.5, 1, 2)
    ]
    assert combos[4].overrides == (("search.alpha", 2), ("search.beta", 1))
    assert variants([]) == [Variant()] and Variant().name == BASE


def test_overrides_create_sections_and_replace_values() -> None:
    data = {"search": {"alpha": 1.0}, "robot": {"start": None}, "map": {"regions": [1, 2]}}
    out = apply_overrides(
        data,
        (("search.beta", 2), ("prediction.svr.C", 100), ("robot.start", {"x": 1, "y": 2})),
    )
    assert out["search"] == {"alpha": 1.0, "beta": 2}
    assert out["prediction"] == {"svr": {"C": 100}}
    assert out["robot"]["start"] == {"x": 1, "y": 2}
    assert data == {"search": {"alpha": 1.0}, "robot": {"start": None}, "map": {"regions": [1, 2]}}
    with pytest.raises(UserError, match=r"map\.regions is a list, not a section"):
        apply_overrides(data, (("map.regions.kitchen", 1),))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("search.alpha", "expected KEY=V1,V2"),
        ("=1", "expected KEY=V1,V2"),
        ("search..alpha=1", "dotted path of mission keys"),
        ("search.alpha=1,,2", "empty value"),
        ("search.alpha=1,1", "given twice"),
        ("search.alpha=[1,2", "is not YAML"),
        ("behavior.tree=@no/such/tree.yaml", "no such file"),
    ],
)
def test_bad_vary_is_one_line(text: str, message: str) -> None:
    with pytest.raises(UserError, match=message) as err:
        parse_vary(text)
    assert str(err.value).startswith(f"--vary {text}: ") and "\n" not in str(err.value)


def test_the_same_key_twice_or_nested_is_refused() -> None:
    with pytest.raises(UserError, match="varied twice"):
        variants([parse_vary("search.alpha=1"), parse_vary("search.alpha=2")])
    with pytest.raises(UserError, match="inside --vary search, which replaces it"):
        variants([parse_vary("search={alpha: 1}"), parse_vary("search.alpha=2")])


def test_variant_missions_are_validated_with_the_mission_rules() -> None:
    (a, b) = variants([parse_vary("search.alpha=2,7.5")])
    base = load_variant(HOUSE_MISSION, Variant())
    assert load_variant(HOUSE_MISSION, a).search.alpha == 2.0
    assert load_variant(HOUSE_MISSION, b).search.alpha == 7.5
    assert len({mission_digest(base), mission_digest(load_variant(HOUSE_MISSION, a))}) == 2
    for text, message in [
        ("search.alpha=abc", r"search\.alpha: expected a valid number"),
        ("search.nope=1", r"search\.nope: unknown key \(expected one of: alpha"),
        ("prediction.svr.C=-1", r"prediction\.svr\.C: expected a value > 0"),
    ]:
        (variant,) = variants([parse_vary(text)])
        with pytest.raises(UserError, match=message) as err:
            load_variant(HOUSE_MISSION, variant)
        assert str(err.value).startswith(f"{HOUSE_MISSION} with --vary {text}: ")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--vary", "search.alpha=abc"], "with --vary search.alpha=abc: search.alpha: expected"),
        (["--vary", "nope"], "--vary nope: expected KEY=V1,V2"),
        (["--task", "dance"], "--task dance: expected one of follow, search"),
        (["--episodes", "0"], "--episodes: expected at least 1"),
        (["--workers", "0"], "--workers: expected at least 1"),
        (["--duration", "-1"], "--duration: expected a positive number"),
    ],
)
def test_bad_arguments_exit_2_and_write_nothing(
    args: list[str],
    message: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "campaign"
    code, _, err = run_cli(
        ["bench", str(HOUSE_MISSION), "--out", str(out), *args], capsys, monkeypatch
    )
    assert code == 2
    assert message in err and err.count("\n") == 1 and err.startswith("pfctl: error: ")
    assert not out.exists()
