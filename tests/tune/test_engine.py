"""The engine: infeasible candidates, metrics equal to a plain `simulate` run, and the Dask
backend for real (`dask scheduler` + two `dask worker` processes on 127.0.0.1, and a
`distributed.LocalCluster` with worker processes), which must give the local run's result
bit for bit (same seed, same batch size)."""

from __future__ import annotations

import json
import shutil
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.cli import main
from armcli.sim.report import joint_metrics
from armcli.sim.simulate import SimConfig, simulate
from armcli.tune import job as tjob
from armcli.tune import session
from armcli.tune.engine import DaskEngine, LocalEngine
from armcli.tune.objective import INFEASIBLE_COST, RMS, Weights
from armcli.tune.problem import nominal_robot
from armcli.tune.search import SearchOptions, cost_of, nominal
from tests.helpers import ROOT, spec_file

SPEC = ROOT / "specs" / "my_robot.yaml"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
OPTS = SearchOptions(trials=8, batch=4, seed=3)
START_TIMEOUT_S = 90  # [s] for the scheduler and both workers to come up (a loaded machine)
STOP_TIMEOUT_S = 20  # [s] for each process to exit after SIGTERM before it is killed
DASK = Path(sys.executable).with_name("dask")


@pytest.fixture(scope="module")
def job() -> tjob.TuneJob:
    settings = tjob.TuneSettings(settle=0.5, robust=2, seed=3)
    return tjob.prepare(spec_file(SPEC), [PICK], settings)


@pytest.fixture(scope="module")
def local(job: tjob.TuneJob) -> session.Outcome:
    return session.run(job, LocalEngine(1), OPTS)


def test_unstable_candidate_is_infeasible(job: tjob.TuneJob) -> None:
    # kp = 1e7 N·m/rad on ~0.01-0.07 kg·m² at dt = 1 ms: wn·dt ~ 12-33, far beyond the
    # implicit-Euler bound (wn·dt < 2 + 2 sqrt(2) even with critical damping).
    n = len(job.problem.joints)
    gains = np.array([1e7] * n + [1.0] * n)
    ev = LocalEngine(1).evaluate(job.problem, [gains], Weights())[0]
    assert not ev.feasible
    assert "loop unstable" in ev.reason
    assert cost_of(ev, OPTS) == INFEASIBLE_COST


def test_metrics_match_a_plain_simulate_run(job: tjob.TuneJob) -> None:
    # The engine's RMS for the nominal model equals sim.report's on a direct simulate call.
    p = nominal(job.problem)
    n = len(p.joints)
    gains = np.concatenate([job.start.kp, job.start.kd])
    ev = LocalEngine(1).evaluate(p, [gains], Weights())[0]
    case = p.cases[0]
    cfg = SimConfig(job.start.kp, job.start.kd, p.dt, p.integrator, p.gravity_comp)
    res = simulate(nominal_robot(p), case.reference, case.q0, case.duration, cfg)
    expected = [m.rms_error for m in joint_metrics(res, case.t_end)]
    assert ev.metrics[0, 0, :n, RMS].tolist() == expected


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _stop(procs: list[subprocess.Popen[Any]]) -> None:
    for p in reversed(procs):
        if p.poll() is None:
            p.terminate()
    for p in reversed(procs):
        try:
            p.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait(timeout=STOP_TIMEOUT_S)


@pytest.fixture(scope="module")
def scheduler_address(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    pytest.importorskip("distributed")
    if not DASK.exists() and shutil.which("dask") is None:
        pytest.skip("the `dask` command is not installed (pip install 'dask[distributed]')")
    exe = str(DASK) if DASK.exists() else "dask"
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    cwd = tmp_path_factory.mktemp("dask")
    common: dict[str, Any] = {
        "cwd": cwd,
        "stdout": subprocess.DEVNULL,
        "stderr": subprocess.DEVNULL,
    }
    procs = [
        subprocess.Popen(
            [exe, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
            **common,
        )
    ]
    try:
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [
                        exe,
                        "worker",
                        address,
                        "--host",
                        "127.0.0.1",
                        "--nthreads",
                        "1",
                        "--nworkers",
                        "1",
                        "--no-dashboard",
                    ],
                    **common,
                )
            )
        from distributed import Client

        with Client(address, timeout=f"{START_TIMEOUT_S}s") as client:
            client.wait_for_workers(2, timeout=START_TIMEOUT_S)
        yield address
    finally:
        _stop(procs)


def _same(a: session.Outcome, b: session.Outcome) -> None:
    assert np.array_equal(a.result.best, b.result.best)
    assert [r.cost for r in a.result.history] == [r.cost for r in b.result.history]
    assert [r.gains.tolist() for r in a.result.history] == [
        r.gains.tolist() for r in b.result.history
    ]


def test_dask_scheduler_and_two_workers(job: tjob.TuneJob, local: session.Outcome,
                                        scheduler_address: str) -> None:  # fmt: skip
    engine = DaskEngine(scheduler_address)
    try:
        assert "2 workers" in engine.name
        remote = session.run(job, engine, OPTS)
    finally:
        engine.close()
    _same(local, remote)


def test_local_cluster_with_processes(job: tjob.TuneJob, local: session.Outcome) -> None:
    distributed = pytest.importorskip("distributed")
    LocalCluster = distributed.LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0", host="127.0.0.1") as cluster:  # fmt: skip
        engine = DaskEngine(cluster.scheduler_address)
        try:
            remote = session.run(job, engine, OPTS)
        finally:
            engine.close()
    _same(local, remote)


def test_cli_scheduler_option_gives_the_local_result(scheduler_address: str,
                                                      tmp_path: Path) -> None:  # fmt: skip
    args = ["tune", str(SPEC), "-t", str(PICK), "--trials", "6", "--batch", "3",
            "--settle", "0.5"]  # fmt: skip
    docs = []
    for extra in ([], ["--scheduler", scheduler_address]):
        out = tmp_path / f"{len(extra)}.json"
        with pytest.raises(SystemExit) as info:
            main([*args, *extra, "-o", str(out)])
        assert info.value.code in (0, None)
        docs.append(json.loads(out.read_text(encoding="utf-8")))
    assert "dask" in docs[1]["search"]["engine"]
    assert docs[0]["best"] == docs[1]["best"]
    assert docs[0]["history"] == docs[1]["history"]
