"""Which link pairs MoveIt may skip in collision checking, computed like its Setup Assistant.

MoveIt checks every pair of links with collision geometry unless the SRDF
disables it. The Setup Assistant disables a pair when checking it is useless:
`Adjacent` (parent and child touch by construction; links without collision
geometry are see-through, so their neighbours count as adjacent), `Default`
(already in collision at the default state, so it would always report a
collision), and `Never` (no collision in any of N random states within the
joint limits). This module does the same with Pinocchio's GeometryModel and
coal, seeded so that the same URDF, sample count and seed give the same matrix.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from armcli.defaults import COLLISION_SAMPLES
from armcli.errors import BuildError, InputError
from armcli.robot import sampling
from armcli.robot.collision import SelfCollision
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf

DEFAULT_SAMPLES = COLLISION_SAMPLES
DEFAULT_SEED = 0
Reason = Literal["Adjacent", "Default", "Never"]  # MoveIt Setup Assistant's words


@dataclass(frozen=True)
class DisabledPair:
    """One SRDF `<disable_collisions>` entry; link1 < link2 alphabetically."""

    link1: str
    link2: str
    reason: Reason


@dataclass(frozen=True)
class EnabledPair:
    """A pair that stays checked, with in how many of the random states it collided."""

    link1: str
    link2: str
    collisions: int


@dataclass(frozen=True)
class CollisionMatrix:
    """The pairs MoveIt may skip and the pairs it checks, with the sampling used.

    `samples` and `seed` reproduce the matrix; `pose_collisions` lists pairs in contact at
    the spec's named poses.
    """

    links: tuple[str, ...]  # links with collision geometry, sorted
    disabled: tuple[DisabledPair, ...]  # sorted by (link1, link2)
    enabled: tuple[EnabledPair, ...]
    samples: int
    seed: int
    pose_collisions: tuple[tuple[str, str, str], ...] = ()  # (pose, link1, link2) in contact

    def reason(self, a: str, b: str) -> Reason | None:
        """Why the pair (a, b) is disabled, or None if MoveIt keeps checking it."""
        key = _pair(a, b)
        return next((d.reason for d in self.disabled if (d.link1, d.link2) == key), None)


def _pair(a: str, b: str) -> tuple[str, str]:
    return (a, b) if a <= b else (b, a)


def adjacent_pairs(urdf: Urdf) -> set[tuple[str, str]]:
    """Parent/child link pairs, bridging links that have no collision geometry (as MoveIt does)."""
    graph: dict[str, set[str]] = {lk.name: set() for lk in urdf.links}
    for j in urdf.joints:
        if j.parent in graph and j.child in graph:
            graph[j.parent].add(j.child)
            graph[j.child].add(j.parent)
    for lk in urdf.links:
        if not lk.collisions:
            for a, b in itertools.combinations(sorted(graph[lk.name]), 2):
                graph[a].add(b)
                graph[b].add(a)
    solid = {lk.name for lk in urdf.links if lk.collisions}
    return {_pair(a, b) for a in solid for b in graph[a] if b in solid and a != b}


class _Sampler:
    """Joint configurations of a robot: MoveIt's default state and seeded random states.

    Mimic joints are not drawn: they follow their leaders, as in MoveIt's RobotState.
    """

    def __init__(self, robot: Robot) -> None:
        model = robot.model
        for jm in list(model.joints)[1:]:
            if jm.nv != 1 or jm.nq not in (1, 2):
                raise BuildError(f"collision matrix: unsupported joint {jm.shortname()}")
        for j in robot.joints:
            if not j.continuous and not (math.isfinite(j.lower) and math.isfinite(j.upper)):
                raise BuildError(f"collision matrix: joint {j.name!r} has no finite limits")
        self.robot = robot
        self.free = robot.leaders
        self.box = sampling.bounds(self.free)

    def _q(self, angles: Iterable[float]) -> np.ndarray:
        names = (j.name for j in self.free)
        return self.robot.q(self.robot.follow(dict(zip(names, angles, strict=True))))

    def _defaults(self) -> dict[str, float]:
        return {j.name: j.rest for j in self.free}

    def default(self) -> np.ndarray:
        """MoveIt's default state: every joint at rest (`robot.joints.rest`, MoveIt's rule).

        0 where the limits allow it, else the middle of the range.
        """
        return self._q(self._defaults().values())

    def named(self, values: dict[str, float]) -> np.ndarray:
        """The default state with the named 1-DoF joints set, and their followers."""
        base = self._defaults()
        base.update((k, v) for k, v in values.items() if k in base)
        return self._q(base.values())

    def random(self, count: int, seed: int) -> Iterator[np.ndarray]:
        """`count` seeded uniform states (`robot.sampling.iter_draws`)."""
        for row in sampling.iter_draws(self.box, count, seed):
            yield self._q(row)


class _Checker:
    """The robot's collision geometry restricted to the candidate link pairs."""

    def __init__(self, robot: Robot, candidates: list[tuple[str, str]]) -> None:
        wanted = set(candidates)
        self.check = SelfCollision(robot, lambda a, b: _pair(a, b) in wanted)
        self.pair_links = [_pair(a, b) for a, b in self.check.pairs]

    def colliding(self, q: np.ndarray, active: Iterable[int]) -> set[tuple[str, str]]:
        """Link pairs in collision at q, testing only the collision pairs in `active`."""
        return {self.pair_links[k] for k in self.check.colliding(q, active)}


def _classify(
    candidates: list[tuple[str, str]],
    adjacent: set[tuple[str, str]],
    default_hits: set[tuple[str, str]],
    seen: set[tuple[str, str]],
    counts: dict[tuple[str, str], int],
) -> tuple[tuple[DisabledPair, ...], tuple[EnabledPair, ...]]:
    """Sort every pair into Adjacent / Default / Never (disabled) or still checked."""
    disabled = [DisabledPair(a, b, "Adjacent") for a, b in adjacent]
    enabled = []
    for a, b in candidates:
        if (a, b) in default_hits:
            disabled.append(DisabledPair(a, b, "Default"))
        elif (a, b) in seen:
            enabled.append(EnabledPair(a, b, counts[(a, b)]))
        else:
            disabled.append(DisabledPair(a, b, "Never"))
    return tuple(sorted(disabled, key=lambda d: (d.link1, d.link2))), tuple(enabled)


def compute_collision_matrix(
    urdf_xml: str | bytes,
    *,
    samples: int = DEFAULT_SAMPLES,
    seed: int = DEFAULT_SEED,
    source: str = "<urdf>",
    poses: dict[str, dict[str, float]] | None = None,
) -> CollisionMatrix:
    """The Setup-Assistant-style collision matrix of a URDF (see the module docstring).

    `poses` (name -> joint values) are extra, deterministic samples: a pair in
    contact at a named pose is never marked `Never`, however rarely the random
    states hit it, and the contacts are returned in `pose_collisions`.
    """
    if samples < 1:
        raise InputError("must be at least 1", field="samples")
    data = urdf_xml.encode("utf-8") if isinstance(urdf_xml, str) else urdf_xml
    urdf = parse_urdf(data, source)
    links = tuple(sorted(lk.name for lk in urdf.links if lk.collisions))
    adjacent = adjacent_pairs(urdf)
    candidates = [p for p in itertools.combinations(links, 2) if p not in adjacent]
    robot = Robot.load(urdf, strict=False)
    checker = _Checker(robot, candidates)
    sampler = _Sampler(robot)
    all_k = range(len(checker.pair_links))
    default_hits = checker.colliding(sampler.default(), all_k)

    active = [k for k in all_k if checker.pair_links[k] not in default_hits]
    in_pose = [
        (name, a, b)
        for name, values in (poses or {}).items()
        for a, b in sorted(checker.colliding(sampler.named(values), active))
    ]
    counts = dict.fromkeys(candidates, 0)
    for q in sampler.random(samples, seed):
        for key in checker.colliding(q, active):
            counts[key] += 1
    seen = {key for key, c in counts.items() if c > 0} | {(a, b) for _, a, b in in_pose}
    disabled, enabled = _classify(candidates, adjacent, default_hits, seen, counts)
    return CollisionMatrix(
        links=links,
        disabled=disabled,
        enabled=enabled,
        samples=samples,
        seed=seed,
        pose_collisions=tuple(in_pose),
    )
