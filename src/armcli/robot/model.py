"""One handle on a robot: Pinocchio model and data, the joint table, mimic couplings, tool.

As pink's `Configuration` and Pinocchio's `RobotWrapper`: code that computes with a
robot asks this class for what it needs instead of building its own. `Robot.q` is the
one place that turns joint values into a Pinocchio configuration: a continuous joint
(revolute without limits) is stored there as the pair (cos, sin) of its angle (nq = 2,
nv = 1). Pinocchio itself is imported inside the functions, so importing this module
keeps `armcli --help` fast.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.errors import InputError
from armcli.robot.frames import reduced_model
from armcli.robot.load import collision_model, load_model
from armcli.robot.mimic import Mimic, follow, mimics
from armcli.robot.tool import ToolPoint, tool_point
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec
    from armcli.urdf.doc import Urdf


@dataclass(frozen=True)
class Joint:
    """One 1-DoF joint of the model: where it sits in q and v, and its URDF numbers."""

    name: str
    idx_q: int
    idx_v: int
    continuous: bool  # stored as (cos, sin) in q
    lower: float  # [rad or m]; -inf for a continuous joint (no stop)
    upper: float  # [rad or m]; inf for a continuous joint
    effort: float  # [N·m or N]; inf when the URDF gives none (<= 0 or not finite)
    velocity: float  # [rad/s or m/s] as the URDF gives it (<= 0 or inf: none)
    damping: float  # [N·m·s/rad or N·s/m]
    friction: float  # [N·m or N]

    @property
    def span(self) -> tuple[float, float]:
        """The finite range to sample it over [rad or m] (`span` of its limits)."""
        return span(self.lower, self.upper)


def _put(q: NDArray[np.float64], joint: Joint, x: float) -> None:
    """Set one joint in q: the angle of a continuous joint as its (cos, sin) pair."""
    if joint.continuous:
        q[joint.idx_q], q[joint.idx_q + 1] = math.cos(x), math.sin(x)
    else:
        q[joint.idx_q] = x


@dataclass(frozen=True)
class JointMap:
    """Where chosen joints and their mimic followers sit in q (`Robot.joint_map`)."""

    template: NDArray[np.float64]  # q with the chosen joints at 0, the others at rest
    lin: tuple[NDArray[np.int64], NDArray[np.int64]]  # (q, x) indices of 1-nq chosen joints
    cont: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]  # (cos, sin, x)
    followers: tuple[tuple[int, bool, str, str, float, float], ...]  # as `Robot.joint_map`
    joints: tuple[str, ...]
    rest: Mapping[str, float]

    def q(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The configuration with the chosen joints at `x` [rad or m]."""
        q = self.template.copy()  # index arrays kept apart: the planner calls this per state
        q[self.lin[0]] = x[self.lin[1]]
        if len(self.cont[2]):
            q[self.cont[0]] = np.cos(x[self.cont[2]])
            q[self.cont[1]] = np.sin(x[self.cont[2]])
        if self.followers:
            values = dict(zip(self.joints, x.tolist(), strict=True))
            for iq, continuous, name, leader, mult, offset in self.followers:  # leaders first
                v = mult * values.get(leader, self.rest.get(leader, 0.0)) + offset
                values[name] = v
                if continuous:  # as `_put`, inlined: per state
                    q[iq], q[iq + 1] = math.cos(v), math.sin(v)
                else:
                    q[iq] = v
        return q


def span(lower: float, upper: float) -> tuple[float, float]:
    """A joint range to sample over [rad or m]: [lower, upper], else [-pi, pi].

    [-pi, pi] when the range is not finite and in order (a continuous joint's is infinite).
    """
    if not (math.isfinite(lower) and math.isfinite(upper)) or lower > upper:
        return -math.pi, math.pi
    return lower, upper


def joint_table(model: Any) -> tuple[Joint, ...]:
    """The model's 1-DoF joints in tree order; multi-DoF joints (floating, planar) are left out."""
    out = []
    for jid in range(1, model.njoints):
        jm = model.joints[jid]
        if jm.nv != 1:
            continue
        continuous = jm.nq == 2
        lo = -math.inf if continuous else float(model.lowerPositionLimit[jm.idx_q])
        hi = math.inf if continuous else float(model.upperPositionLimit[jm.idx_q])
        effort = float(model.effortLimit[jm.idx_v])
        out.append(
            Joint(
                name=str(model.names[jid]),
                idx_q=int(jm.idx_q),
                idx_v=int(jm.idx_v),
                continuous=continuous,
                lower=lo,
                upper=hi,
                effort=effort if effort > 0 and math.isfinite(effort) else math.inf,
                velocity=float(model.velocityLimit[jm.idx_v]),
                damping=float(model.damping[jm.idx_v]),
                friction=float(model.friction[jm.idx_v]),
            )
        )
    return tuple(out)


class Robot:
    """A Pinocchio model with its joint table, mimic couplings and tool point.

    `joints` are the 1-DoF joints in tree order; `mimics` the URDF's couplings (leaders
    first; a follower is never set on its own); `tool` the end-effector point
    (`robot.tool`), None for a model without links. `xml` and `urdf` are the URDF text
    and document the model came from, kept for the collision geometry.
    """

    def __init__(
        self,
        model: Any,
        *,
        mimics: Iterable[Mimic] = (),
        tool: ToolPoint | None = None,
        source: str = "<model>",
        xml: str | None = None,
        urdf: Urdf | None = None,
        parser_messages: Sequence[str] = (),
    ) -> None:
        """Wrap `model` (a pinocchio.Model); see the class docstring for the rest."""
        self.model = model
        self.joints = joint_table(model)
        names = {j.name for j in self.joints}
        self.mimics = tuple(m for m in mimics if m.leader in names and m.follower in names)
        self.tool = tool
        self.source = source
        self.xml = xml
        self.urdf = urdf
        self.parser_messages = tuple(parser_messages)
        self._by_name = {j.name: j for j in self.joints}
        self._data: Any = None
        self._neutral: NDArray[np.float64] | None = None

    @classmethod
    def from_xml(
        cls,
        xml: str,
        source: str = "<urdf>",
        *,
        floating: bool = False,
        mimics: Iterable[Mimic] = (),
        tool: ToolPoint | None = None,
        urdf: Urdf | None = None,
    ) -> Robot:
        """Load URDF text (`floating`: the root on a free-flyer joint); ModelLoadError if bad."""
        loaded = load_model(source, xml=xml, floating=floating)
        return cls(loaded.model, mimics=mimics, tool=tool, source=source, xml=xml, urdf=urdf,
                   parser_messages=loaded.parser_messages)  # fmt: skip

    @classmethod
    def from_urdf(
        cls, urdf: Urdf, *, floating: bool = False, spec: RobotSpec | None = None
    ) -> Robot:
        """A parsed URDF's robot, with its mimic couplings and tool point (the spec's, if any)."""
        try:
            xml = urdf.text.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError("URDF is not UTF-8 text", file=urdf.source) from None
        return cls.from_xml(xml, urdf.source, floating=floating, mimics=mimics(urdf.joints),
                            tool=tool_point(urdf, spec), urdf=urdf)  # fmt: skip

    @property
    def data(self) -> Any:
        """The model's pinocchio.Data, created on first use and shared by this handle's users."""
        if self._data is None:
            self._data = self.model.createData()
        return self._data

    @property
    def names(self) -> tuple[str, ...]:
        """The 1-DoF joints' names in tree order."""
        return tuple(j.name for j in self.joints)

    @property
    def leaders(self) -> tuple[Joint, ...]:
        """The joints that are set on their own: every 1-DoF joint but the mimic followers."""
        followers = {m.follower for m in self.mimics}
        return tuple(j for j in self.joints if j.name not in followers)

    @property
    def mass(self) -> float:
        """The total mass of the model's bodies [kg]."""
        return float(sum(inertia.mass for inertia in self.model.inertias))

    def joint(self, name: str) -> Joint:
        """The joint called `name`; InputError listing the valid names otherwise."""
        try:
            return self._by_name[name]
        except KeyError:
            raise InputError(
                f"unknown joint {name!r}; valid: {', '.join(self.names)}", field="joints"
            ) from None

    def neutral(self) -> NDArray[np.float64]:
        """Pinocchio's neutral configuration (every joint at 0, the free-flyer at identity)."""
        if self._neutral is None:
            import pinocchio as pin

            self._neutral = np.asarray(pin.neutral(self.model), dtype=float)
        return self._neutral.copy()

    def follow(self, values: Mapping[str, float]) -> dict[str, float]:
        """`values` with every mimic follower of a given leader set from it."""
        return follow(self.mimics, values)

    def q(
        self,
        values: Mapping[str, float] | ArrayLike = (),
        *,
        joints: Sequence[Joint] | None = None,
        base: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """The configuration with joints set to `values` [rad or m]; the rest from `base`.

        `values` is a mapping by joint name (names that are not 1-DoF joints of the model
        are ignored) or a sequence aligned with `joints` (default: every joint, tree
        order). `base` defaults to the neutral configuration. Mimic followers are not
        moved here: `follow` the values first.
        """
        q = self.neutral() if base is None else np.array(base, dtype=float)
        if isinstance(values, Mapping):
            pairs: Iterable[tuple[Joint, Any]] = (
                (self._by_name[n], x) for n, x in values.items() if n in self._by_name
            )
        else:
            chosen = self.joints if joints is None else joints
            pairs = zip(chosen, np.asarray(values, dtype=float).reshape(-1), strict=True)
        for j, x in pairs:
            _put(q, j, float(x))
        return q

    def joint_map(self, joints: Sequence[str], rest: Mapping[str, float] | None = None) -> JointMap:
        """`x` (values of `joints`, in order) -> q, vectorised: for a caller building q per state.

        A planner's validity check calls it per state. Other joints at `rest` (else
        neutral), followers following their leaders: the same q as `q(follow(...))`.
        """
        rest = dict(rest or {})
        chosen = [self.joint(n) for n in joints]
        template = self.q(self.follow({**rest, **{j.name: 0.0 for j in chosen}}))

        def indices(continuous: bool) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
            pairs = [(j.idx_q, k) for k, j in enumerate(chosen) if j.continuous == continuous]
            table = np.array(pairs, dtype=np.int64).reshape(-1, 2)
            return table[:, 0].copy(), table[:, 1].copy()

        (lq, lx), (cq, cx) = indices(False), indices(True)
        by_name = self._by_name
        followers = tuple((by_name[m.follower].idx_q, by_name[m.follower].continuous, m.follower,
                           m.leader, m.multiplier, m.offset)
                          for m in self.mimics if m.follower in by_name)  # fmt: skip
        return JointMap(template, (lq, lx), (cq, cq + 1, cx), followers, tuple(joints), rest)

    def reduced(self, joints: Sequence[str]) -> Robot:
        """The robot with only `joints` movable; the others locked at their neutral value.

        InputError (field `joints`) for an unknown joint or one listed twice.
        """
        import pinocchio as pin

        names = list(self.model.names)[1:]
        for name in joints:
            if name not in names:
                raise InputError(f"unknown joint {name!r}; valid: {', '.join(names)}",
                                 field="joints")  # fmt: skip
        if len(set(joints)) != len(joints):
            raise InputError("a joint is listed twice", field="joints")
        lock = [self.model.getJointId(nm) for nm in names if nm not in joints]
        if not lock:
            return self
        model = reduced_model(self.model, lock, pin.neutral(self.model))  # names may clash
        return Robot(model, mimics=self.mimics, tool=self.tool, source=self.source, xml=self.xml,
                     urdf=self.urdf, parser_messages=self.parser_messages)  # fmt: skip

    def collision_model(self, search: MeshSearch | None = None) -> Any:
        """The URDF's collision geometry, a pinocchio.GeometryModel, built on demand.

        With `search` (the package lookup), every collision mesh is resolved inside the
        allowed roots and bounded first (`urdf.meshes.confined_mesh_xml`: `check`, `plan`;
        visual meshes are not loaded, so one in a package absent here does not matter);
        without it the URDF text is read as it is (its meshes resolved by the caller).
        InputError without a URDF (text) or for a mesh not found or over the size caps;
        ModelLoadError when Pinocchio refuses the geometry.
        """
        if search is not None and self.urdf is not None:
            text: str | None = confined_mesh_xml(
                self.urdf.text, self.urdf.source, search, collision_only=True
            )
        elif search is not None:
            raise InputError("no URDF document to resolve meshes in", file=self.source)
        else:
            text = self.xml
        if text is None:
            raise InputError("no URDF text to read collision geometry from", file=self.source)
        return collision_model(self.model, text, [], self.source)
