"""The compiled RRT-Connect: free paths by the Python checker, seeds, threads and restarts."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from armcli.plan.collision import PADDING
from armcli.plan.inputs import Loaded
from armcli.plan.native import load
from tests.plan.test_collision import STEP, python_twin

pytestmark = pytest.mark.skipif(load() is None, reason="the compiled planner is not built")
OPTIONS = {"range": 1.0, "goal_bias": 0.05, "step": STEP, "timeout": 30.0}


def blocked_pairs(loaded: Loaded, count: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Free start/goal pairs whose straight segment collides."""
    ck, robot = loaded.context.checker, loaded.context.robot
    rng = np.random.default_rng(seed)
    out: list[tuple[np.ndarray, np.ndarray]] = []
    while len(out) < count:
        a, b = rng.uniform(robot.lower, robot.upper, (2, len(robot.joints)))
        if ck.first_collision(a, every_pair=True) or ck.first_collision(b, every_pair=True):
            continue
        if not ck.motion_free(a, b, STEP):
            out.append((a, b))
    return out


def test_paths_are_free_by_the_python_checker(panda_bin: Loaded) -> None:
    native, python = panda_bin.context.checker.native, python_twin(panda_bin)
    assert native is not None
    for k, (a, b) in enumerate(blocked_pairs(panda_bin, 4, 2)):
        for ck in (panda_bin.context.checker, python):
            ck.pad(PADDING, (a, b))
        path, stats = native.plan(a, b, seed=k, threads=1, attempt_nodes=20_000, **OPTIONS)
        assert path is not None and stats["attempt"] == 0
        assert np.array_equal(path[0], a) and np.array_equal(path[-1], b)
        assert all(python.motion_free(p, q, STEP) for p, q in itertools.pairwise(path))
        short = native.shortcut(path, STEP, k, 100, 20)
        assert np.array_equal(short[0], a) and np.array_equal(short[-1], b)
        assert all(python.motion_free(p, q, STEP) for p, q in itertools.pairwise(short))
        length = lambda p: np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1))  # noqa: E731
        assert length(short) <= length(path) + 1e-12


def test_a_seed_gives_one_path_at_any_thread_count(panda_bin: Loaded) -> None:
    native = panda_bin.context.checker.native
    assert native is not None
    ((a, b),) = blocked_pairs(panda_bin, 1, 3)
    panda_bin.context.checker.pad(PADDING, (a, b))
    # small attempts, so that several run (and later ones may finish first on threads)
    runs = [native.plan(a, b, seed=7, threads=t, attempt_nodes=40, **OPTIONS) for t in (1, 2, 2)]
    paths = [p for p, _ in runs if p is not None]
    assert len(paths) == 3
    assert all(np.array_equal(paths[0], p) for p in paths[1:])
    assert len({s["attempt"] for _, s in runs}) == 1
    other, _ = native.plan(a, b, seed=8, threads=1, attempt_nodes=40, **OPTIONS)
    assert other is not None and not np.array_equal(other, paths[0])


def test_a_stalled_attempt_gives_way_to_the_next_seed(panda_bin: Loaded) -> None:
    native = panda_bin.context.checker.native
    assert native is not None
    found = []
    for a, b in blocked_pairs(panda_bin, 6, 4):
        panda_bin.context.checker.pad(PADDING, (a, b))
        path, stats = native.plan(a, b, seed=0, threads=1, attempt_nodes=2, **OPTIONS)
        assert path is not None
        found.append(stats["attempt"])
    assert max(found) > 0  # one round per attempt: later seeds solved some


@pytest.mark.parametrize("lazy_step", [0.5, 5.0])
def test_lazy_edges_are_checked_at_the_step(panda_bin: Loaded, lazy_step: float) -> None:
    # 5 rad: beyond the range, so tree edges are checked at their ends only and many a
    # path the trees meet along has an edge through the clutter, cut off and searched again
    native, python = panda_bin.context.checker.native, python_twin(panda_bin)
    assert native is not None
    for k, (a, b) in enumerate(blocked_pairs(panda_bin, 4, 6)):
        for ck in (panda_bin.context.checker, python):
            ck.pad(PADDING, (a, b))
        path, _ = native.plan(a, b, seed=k, threads=1, attempt_nodes=20_000,
                              lazy_step=lazy_step, **OPTIONS)  # fmt: skip
        assert path is not None
        assert np.array_equal(path[0], a) and np.array_equal(path[-1], b)
        assert all(python.motion_free(p, q, STEP) for p, q in itertools.pairwise(path))
