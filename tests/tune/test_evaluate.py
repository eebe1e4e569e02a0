"""What a candidate costs (issue 24): the work shared by every candidate is done once.

Scoring N candidates samples each case's reference once and linearises each model once
(M(q) and gravity's stiffness at the samples); per candidate only the rollouts and the
stability verdict itself (one batched factorisation of A at the samples) remain. The
pre-sampled tables give the same numbers as sampling per run.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from armcli.sim import simulate as sim
from armcli.sim import stability as stab
from armcli.spec.load import load_spec
from armcli.tune import evaluate, problem
from armcli.tune import job as tjob
from armcli.tune.objective import Weights
from tests.helpers import ROOT

SPEC = ROOT / "specs" / "my_robot.yaml"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
WAVE = ROOT / "specs" / "trajectories" / "wave.yaml"
CANDIDATES = 5


@pytest.fixture(scope="module")
def job() -> tjob.TuneJob:
    settings = tjob.TuneSettings(settle=0.3, robust=2, seed=1)
    return tjob.prepare(load_spec(SPEC), SPEC, [PICK, WAVE], settings)


def _batch(job: tjob.TuneJob) -> list[np.ndarray]:
    start = np.concatenate([job.start.kp, job.start.kd])
    return [start * (1.0 + 0.05 * k) for k in range(CANDIDATES)]


def _counting(monkeypatch: pytest.MonkeyPatch, module: Any, name: str) -> list[int]:
    calls = [0]
    real = getattr(module, name)

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)
    return calls


def test_shared_work_is_done_once_per_case_and_model(
    job: tjob.TuneJob, monkeypatch: pytest.MonkeyPatch
) -> None:
    fresh = job.problem.with_key()  # a new key: the per-process caches start empty
    monkeypatch.setattr(problem, "_CACHE", {})
    monkeypatch.setattr(problem, "_SAMPLED", {})
    sampled = _counting(monkeypatch, problem, "sample_reference")
    per_run = _counting(monkeypatch, sim, "sample_reference")
    linearised = _counting(monkeypatch, stab, "linearise")
    evs = evaluate.evaluate_candidates(fresh, _batch(job), Weights())
    assert all(ev.feasible for ev in evs)
    assert sampled[0] == len(fresh.cases)  # once per case, not per candidate or model
    assert per_run[0] == 0  # no rollout samples its own reference
    assert linearised[0] == len(fresh.variants)  # once per model


def test_presampled_reference_gives_the_same_numbers(job: tjob.TuneJob) -> None:
    """A run given its tables equals one that samples them itself, to the bit."""
    sm = problem.scored_models(job.problem)[0]
    case, table = job.problem.cases[0], problem.sampled_cases(job.problem)[0]
    cfg = sim.SimConfig(job.start.kp, job.start.kd, job.problem.dt)
    own, given = sim.simulate_batch(
        [
            sim.Run(sm.arm, case.reference, case.q0, case.duration, cfg),
            sim.Run(sm.arm, case.reference, case.q0, case.duration, cfg, table),
        ]
    )
    assert isinstance(own, sim.SimResult) and isinstance(given, sim.SimResult)
    np.testing.assert_array_equal(own.q, given.q)
    np.testing.assert_array_equal(own.tau, given.tau)
