"""The allowed-collision matrix cache: a hit is the computed matrix; a bad file is never trusted."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from armcli.plan import matrixcache
from armcli.plan.srdf import allowed_pairs
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ARMCLI_CACHE_DIR", str(tmp_path))
    return tmp_path / "acm"


def computed(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Count the computations (the real one runs)."""
    calls: list[int] = []
    real = matrixcache.cached_pairs

    def counting(key, links, compute):
        def wrapped():
            calls.append(1)
            return compute()

        return real(key, links, wrapped)

    monkeypatch.setattr("armcli.plan.srdf.cached_pairs", counting)
    return calls


def test_a_hit_is_the_computed_matrix(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = computed(monkeypatch)
    robot = read_robot(DEFAULT_SPEC)
    first = allowed_pairs(robot, None)
    assert calls == [1] and len(list(cache.iterdir())) == 1
    again = allowed_pairs(robot, None)
    assert again == first and calls == [1]  # read back, not computed


@pytest.mark.parametrize(
    "tamper",
    [
        lambda d: {**d, "disabled": [["base_link", "no_such_link"]]},  # a link not of this robot
        lambda d: {**d, "disabled": [["a"]]},  # not a pair
        lambda d: {**d, "key": "0" * 64},  # another robot's
        lambda d: {**d, "format": 0},
        lambda d: {**d, "extra": 1},
        lambda d: "not a mapping",
    ],
)
def test_a_bad_cache_file_is_recomputed(
    cache: Path, monkeypatch: pytest.MonkeyPatch, tamper: object
) -> None:
    robot = read_robot(DEFAULT_SPEC)
    first = allowed_pairs(robot, None)
    (path,) = cache.iterdir()
    path.write_text(json.dumps(tamper(json.loads(path.read_text()))))  # type: ignore[operator]
    calls = computed(monkeypatch)
    assert allowed_pairs(robot, None) == first and calls == [1]


def test_a_garbled_or_huge_file_is_recomputed(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    robot = read_robot(DEFAULT_SPEC)
    first = allowed_pairs(robot, None)
    (path,) = cache.iterdir()
    for junk in (b"\xff{", b" " * (matrixcache.MAX_CACHE_BYTES + 1)):
        path.write_bytes(junk)
        calls = computed(monkeypatch)
        assert allowed_pairs(robot, None) == first and calls == [1]


def test_an_unwritable_cache_only_costs_time(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("ARMCLI_CACHE_DIR", str(blocker))  # acm/ cannot be made under a file
    robot = read_robot(DEFAULT_SPEC)
    assert allowed_pairs(robot, None)  # computed; nothing raised


def test_the_key_follows_the_meshes(tmp_path: Path) -> None:
    mesh = tmp_path / "m.stl"
    mesh.write_bytes(b"solid a\nendsolid a\n")
    text = f'<robot name="r"><link name="a"><collision><geometry><mesh filename="{mesh}"/>' \
           "</geometry></collision></link></robot>"  # fmt: skip
    before = matrixcache.matrix_key(text, None, 10, 0)
    mesh.write_bytes(b"solid b\nendsolid b\n")
    assert matrixcache.matrix_key(text, None, 10, 0) != before
    assert matrixcache.matrix_key(text, None, 11, 0) != matrixcache.matrix_key(text, None, 10, 0)
