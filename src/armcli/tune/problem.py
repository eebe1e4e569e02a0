"""What a tuning evaluates: the arm (as URDF text), the cases and the perturbed models.

A `TuneProblem` is plain picklable data so that it can be shipped once to every Dask
worker; `scored_models` loads the robot (`Robot.load`) on first use in each process and
caches its variants under the problem's content key, so a worker pays for the URDF parse
once.
"""

from __future__ import annotations

import hashlib
import pickle
import threading
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from armcli.analysis.pdloop import Linearised
from armcli.defaults import PdLoop
from armcli.robot.model import Robot
from armcli.sim.options import Integrator
from armcli.sim.simulate import simulated
from armcli.trajectory.reference import Reference
from armcli.tune.model_gains import linearised, sample_configurations
from armcli.urdf.read import parse_urdf

_CACHE: dict[str, tuple[Scored, ...]] = {}
_LOCK = threading.Lock()


@dataclass(frozen=True, eq=False)
class Scored:
    """One model candidates are scored on, with its inertia sample for the stability check."""

    robot: Robot
    qs: np.ndarray  # (S, n) sampled configurations
    lin: Linearised  # M(q) and gravity's stiffness at each sample


@dataclass(frozen=True, eq=False)
class Case:
    """One closed-loop run: start at rest at `q0`, track `reference` for `duration` [s]."""

    label: str
    reference: Reference
    q0: np.ndarray
    t_end: float  # [s] time of the trajectory's last point
    duration: float  # [s] simulated time (t_end + settle window)


@dataclass(frozen=True)
class Variant:
    """A perturbed model: every body's mass and inertia scaled, every joint's friction."""

    mass_scale: tuple[float, ...]  # per body of the reduced model, in model order
    friction_scale: tuple[float, ...]  # per simulated joint


@dataclass(frozen=True)
class TuneProblem:
    """Everything a worker needs to score a candidate; immutable and picklable."""

    urdf_xml: str
    urdf_name: str
    joints: tuple[str, ...]
    dt: float  # [s]
    integrator: Integrator
    gravity_comp: bool
    loop: PdLoop  # which stability bound makes a candidate infeasible
    stability_margin: float  # nominal model: stable at stability_margin * dt; variants: at dt
    cases: tuple[Case, ...]
    variants: tuple[Variant, ...]  # empty: the nominal model only
    key: str = field(default="", compare=False)

    def with_key(self) -> TuneProblem:
        """The same problem tagged with a digest of its content (the worker cache key)."""
        blob = pickle.dumps(replace(self, key=""), protocol=5)
        return replace(self, key=hashlib.sha256(blob).hexdigest()[:16])


def nominal_robot(problem: TuneProblem) -> Robot:
    """The unperturbed robot of `problem`: its joints movable, the others locked."""
    urdf = parse_urdf(problem.urdf_xml.encode("utf-8"), problem.urdf_name)
    return simulated(Robot.load(urdf), list(problem.joints))


def perturb(robot: Robot, variant: Variant) -> Robot:
    """`robot` with scaled masses/inertias (same centre of mass) and scaled friction."""
    return robot.scaled(variant.mass_scale, variant.friction_scale)


def scored_models(problem: TuneProblem) -> tuple[Scored, ...]:
    """The models every candidate is scored on: the variants, or the nominal arm alone.

    Built once per process and cached under the problem's key.
    """
    key = problem.key or problem.with_key().key
    with _LOCK:
        if key not in _CACHE:
            robot = nominal_robot(problem)
            qs = sample_configurations(robot)
            built = tuple(perturb(robot, v) for v in problem.variants) or (robot,)
            gravity = not problem.gravity_comp
            _CACHE[key] = tuple(Scored(a, qs, linearised(a, qs, gravity=gravity)) for a in built)
        return _CACHE[key]


def draw_variants(
    robot: Robot,
    count: int,
    mass_range: tuple[float, float],
    friction_range: tuple[float, float],
    seed: int,
) -> tuple[Variant, ...]:
    """`count` perturbed models, scales uniform in the given ranges, from a seeded stream."""
    rng = np.random.default_rng(seed)
    bodies = robot.model.njoints - 1
    n = len(robot.names)
    out = []
    for _ in range(count):
        ms = rng.uniform(mass_range[0], mass_range[1], size=bodies)
        fs = rng.uniform(friction_range[0], friction_range[1], size=n)
        out.append(Variant(tuple(float(x) for x in ms), tuple(float(x) for x in fs)))
    return tuple(out)


def describe(problem: TuneProblem) -> dict[str, Any]:
    """A JSON-ready summary of the problem (for the output file)."""
    return {
        "joints": list(problem.joints),
        "dt": problem.dt,
        "integrator": problem.integrator,
        "gravity_compensation": problem.gravity_comp,
        "loop": problem.loop,
        "stability_margin": problem.stability_margin,
        "cases": [
            {"label": c.label, "t_end": c.t_end, "duration": c.duration} for c in problem.cases
        ],
        "variants": [
            {"mass_scale": list(v.mass_scale), "friction_scale": list(v.friction_scale)}
            for v in problem.variants
        ],
    }
