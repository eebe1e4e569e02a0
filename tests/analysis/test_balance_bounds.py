"""The balance search is bounded (issue 31): TIAGo dual (25 joints on a 37-edge round
base) took 307,000 centre-of-mass Jacobians and 12 CPU s of `check`; the bounded search
spends at most MAX_JACOBIANS and still finds a configuration at least as bad as any of
a brute-force sample (an independent lower bound on how far the search must get)."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

from armcli.analysis import balance
from armcli.analysis.stance import Stance
from armcli.check.run import check_urdf
from armcli.urdf.read import read_urdf

BRUTE = 2000  # random configurations of the brute-force reference
SEED = 31
SEARCH_TOL = 1e-4  # [m] the search may fall short of the brute-force least margin by this


def _tiago_dual() -> Path | None:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    rel = "cmeel.prefix/share/example-robot-data/robots/tiago_description/robots/tiago_dual.urdf"
    path = Path(str(dist.locate_file(rel)))
    return path if path.is_file() else None


def test_many_joints_on_a_round_base_stay_within_the_budget(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    path = _tiago_dual()
    if path is None:
        pytest.skip("example-robot-data is not installed (pip install -e '.[dev]')")
    made: list[balance._Mass] = []
    init = balance._Mass.__init__

    def spy(self: balance._Mass, s: Stance) -> None:
        init(self, s)
        made.append(self)

    monkeypatch.setattr(balance._Mass, "__init__", spy)
    summary = check_urdf(read_urdf(path)).summary  # with the tool point as payload point
    assert summary is not None and summary.balance is not None
    assert made[0].jacobians <= balance.MAX_JACOBIANS + 1000  # a descent ends its step
    least = min(p.margin for p in summary.balance.worst)
    stance = made[0].s  # the stance check analysed (its contacts from the meshes)
    assert len(stance.joints) >= 20
    rng = np.random.default_rng(SEED)
    lower, upper = np.array(stance.box).T
    ev = balance._Mass(stance)
    brute = min(
        stance.polygon.margin(ev.com(x, 0.0))
        for x in rng.uniform(lower, upper, (BRUTE, len(lower)))
    )
    assert least <= brute + SEARCH_TOL
