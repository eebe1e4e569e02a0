"""What a candidate costs (issue 24): the work shared by every candidate is done once.

Scoring N candidates linearises each model once (M(q) and gravity's stiffness at the
samples) and never samples a reference in Python (the compiled engine evaluates the
trajectory's polynomials itself); per candidate only the rollouts and the stability
verdict itself (one batched factorisation of A at the samples) remain.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from armcli.trajectory.reference import Reference
from armcli.tune import evaluate, problem
from armcli.tune import job as tjob
from armcli.tune.objective import Weights
from tests.analysis import stability_reference as ref
from tests.helpers import ROOT, spec_file

SPEC = ROOT / "specs" / "my_robot.yaml"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
WAVE = ROOT / "specs" / "trajectories" / "wave.yaml"
CANDIDATES = 5


@pytest.fixture(scope="module")
def job() -> tjob.TuneJob:
    settings = tjob.TuneSettings(settle=0.3, robust=2, seed=1)
    return tjob.prepare(spec_file(SPEC), [PICK, WAVE], settings)


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


def test_shared_work_is_done_once_per_model(
    job: tjob.TuneJob, monkeypatch: pytest.MonkeyPatch
) -> None:
    fresh = job.problem.with_key()  # a new key: the per-process cache starts empty
    monkeypatch.setattr(problem, "_CACHE", {})
    sampled = _counting(monkeypatch, Reference, "sample")
    linearised = _counting(monkeypatch, pdloop, "linearise")
    evs = evaluate.evaluate_candidates(fresh, _batch(job), Weights())
    assert all(ev.feasible for ev in evs)
    assert sampled[0] == 0  # no reference is sampled per candidate (nor at all)
    assert linearised[0] == len(fresh.variants)  # once per model, not per candidate


def test_stability_verdict_per_candidate_is_the_bound(job: tjob.TuneJob) -> None:
    """The batched factorisation judges as the eigenvalues of the step map do."""
    sm = problem.scored_models(job.problem)[0]
    n = len(job.problem.joints)
    Ms, Gs = list(sm.lin.M), list(sm.lin.G)
    for scale in (1.0, 30.0, 1e3, 1e5):
        kp = job.start.kp * scale
        pd = pdloop.PD.of(range(n), kp, job.start.kd, sm.robot.damping)
        d = job.start.kd + sm.robot.damping
        rho = ref.worst_radius(Ms, Gs, range(n), kp, d, job.problem.dt, "implicit")
        assert stab.stable(sm.lin, pd, job.problem.dt, "implicit") == (rho <= 1 + ref.RADIUS_TOL)


def test_a_rollout_keeps_only_the_states_its_metrics_read(job: tjob.TuneJob) -> None:
    """Tune's rollouts keep the states from the last trajectory point on (the copy out of
    the engine holds the GIL); their metrics equal those of the whole trace, bit for bit."""
    from armcli.sim.simulate import SimConfig, simulate
    from armcli.tune.objective import run_metrics

    sm = problem.scored_models(job.problem)[0]
    kp, kd = np.split(_batch(job)[2], 2)
    cfg = SimConfig(kp, kd, job.problem.dt, job.problem.integrator, job.problem.gravity_comp)
    for case in job.problem.cases:
        (kept,) = evaluate.rollout_batch([evaluate.RolloutJob(sm.robot, case, cfg)])
        whole = simulate(sm.robot, case.reference, case.q0, case.duration, cfg)
        assert kept is not None
        assert kept.step[0] == round(case.t_end / cfg.dt) and kept.step[-1] == whole.steps
        assert kept.q.shape[0] < whole.q.shape[0] / 2
        assert np.array_equal(run_metrics(kept, case.t_end), run_metrics(whole, case.t_end))
