"""Safe YAML reader: line numbers, and the PyYAML behaviours it refuses."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.io.yaml import MAX_YAML_BYTES, load_yaml, loads_yaml


def test_line_numbers_follow_paths() -> None:
    doc = loads_yaml("a:\n  b: 1\n  c:\n    - 2\n    - {d: 3}\n")
    assert doc.data == {"a": {"b": 1, "c": [2, {"d": 3}]}}
    assert doc.line_of(("a", "b")) == 2
    assert doc.line_of(("a", "c", 1, "d")) == 5
    assert doc.line_of(("a", "c", 1, "missing")) == 5  # falls back to the parent


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("a: 1\na: 2\n", "duplicate key 'a'"),
        ("a: &x [1, 2]\nb: *x\n", "anchors/aliases"),
        ("a: [1, 2\n", "malformed YAML"),
        ("a: \x00\n", "NUL"),
        ("[" * 100 + "]" * 100, "nesting deeper"),
        # deep enough that PyYAML's own scanner guard fires first: the same armcli message
        ("a: " + "[" * 5000 + "]" * 5000, "nesting deeper than 64 levels"),
    ],
)
def test_refusals(text: str, fragment: str) -> None:
    with pytest.raises(InputError, match=fragment):
        loads_yaml(text, "f.yaml")


def test_alias_bomb_refused_before_expansion() -> None:
    # The classic billion-laughs YAML: each level doubles; safe_load would build 2**30 items.
    lines = ["a0: &a0 [x, x]"] + [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}]" for i in range(1, 31)]
    with pytest.raises(InputError, match="anchors/aliases"):
        loads_yaml("\n".join(lines))


def test_duplicate_key_reports_line() -> None:
    with pytest.raises(InputError) as info:
        loads_yaml("x: 1\ny:\n  z: 1\n  z: 2\n", "f.yaml")
    assert str(info.value).startswith("f.yaml:4 y.z: duplicate key")


def test_ros_flow_set_quirk() -> None:
    doc = loads_yaml("positions: {0.0, 0.5}\n", flow_sets=True)
    assert doc.data == {"positions": [0.0, 0.5]}
    with pytest.raises(InputError, match="duplicate"):
        loads_yaml("positions: {0.0, 0.0}\n")  # without the quirk it is a bad mapping
    assert loads_yaml("positions: {0.0, 0.0}\n", flow_sets=True).data == {"positions": [0.0, 0.0]}


def test_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not found"):
        load_yaml(tmp_path / "missing.yaml")
    with pytest.raises(InputError, match="is a directory"):
        load_yaml(tmp_path)
    big = tmp_path / "big.yaml"
    big.write_text("a: " + "x" * MAX_YAML_BYTES)
    with pytest.raises(InputError, match="larger than"):
        load_yaml(big)
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(InputError, match="not UTF-8"):
        load_yaml(binary)


def test_a_tab_is_named_as_a_tab() -> None:
    # libyaml says "found character that cannot start any token", hiding the character
    with pytest.raises(InputError, match=r"a tab character, column 1; YAML indents with spaces"):
        loads_yaml("name: x\n\tarm: 1\n", "spec.yaml")


def test_a_ros2_topic_echo_file_ending_in_dashes_is_one_document() -> None:
    echo = "joint_names:\n- a\npoints:\n- positions:\n  - 0.1\n---\n"  # as `ros2 topic echo`
    assert loads_yaml(echo).data == {"joint_names": ["a"], "points": [{"positions": [0.1]}]}
    with pytest.raises(InputError, match="malformed YAML"):  # a second message is not dropped
        loads_yaml(echo + "joint_names: [b]\n")
