"""One handle on a robot: model and data, joints and limits, mimic couplings, tool, kinematics.

As pink's `Configuration` and Pinocchio's `RobotWrapper`: code that computes with a robot
asks this class for what it needs instead of building its own. `Robot.load` is the one
loader. The kinematics (`frame_pose`, `tool_position`, `jacobian`, `mass_matrix`,
`gravity`, ...) are its methods, inherited from `robot.kinematics.Kinematics`. The limit
arrays (`lower`, `upper`, `effort`, `velocity`, `damping`, `friction`, per joint of
`joints`) are read-only views of the model's, so a variant of the robot (other limits,
scaled masses, a payload) is a new `Robot` over a copied model (`with_limits`, `scaled`,
`with_point_mass`), never an edited copy of a table. Where an unset joint rests is
`robot.joints.rest`'s rule. Pinocchio is imported inside the functions, so importing this
module keeps `armcli --help` fast.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.errors import InputError
from armcli.robot.frames import reduced_model
from armcli.robot.joints import Joint, JointMap, joint_table, put
from armcli.robot.kinematics import Kinematics
from armcli.robot.load import checked_model, collision_model, load_model
from armcli.robot.mimic import Mimic, follow, mimics
from armcli.robot.tool import ToolPoint, tool_point
from armcli.urdf.meshes import MeshSearch, confined_mesh_xml
from armcli.urdf.source import urdf_text

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec
    from armcli.urdf.doc import Urdf

LIMITS = ("lower", "upper", "effort", "velocity", "damping", "friction")  # the limit arrays


def _readonly(values: Iterable[float]) -> NDArray[np.float64]:
    out = np.array(list(values), dtype=float)
    out.flags.writeable = False
    return out


class Robot(Kinematics):
    """A Pinocchio model with its joints, limits, mimic couplings, tool point and kinematics.

    `joints` are the 1-DoF joints in tree order, and the limit arrays follow that order;
    `mimics` the URDF's couplings (leaders first; a follower is never set on its own);
    `tool` the end-effector point, None for a model without links. `xml` and `urdf` are
    the URDF text and document the model came from, kept for the collision geometry.
    """

    lower: NDArray[np.float64]  # [rad or m]; -inf: no stop (a continuous joint)
    upper: NDArray[np.float64]  # [rad or m]; inf: no stop
    effort: NDArray[np.float64]  # [N·m or N]; inf when the URDF gives none
    velocity: NDArray[np.float64]  # [rad/s or m/s] as the URDF gives it (<= 0 or inf: none)
    damping: NDArray[np.float64]  # [N·m·s/rad or N·s/m]
    friction: NDArray[np.float64]  # [N·m or N]

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
        self.tool, self.source, self.xml, self.urdf = tool, source, xml, urdf
        self.parser_messages = tuple(parser_messages)
        for name in LIMITS:
            setattr(self, name, _readonly(getattr(j, name) for j in self.joints))
        self._by_name = {j.name: j for j in self.joints}
        self._local = threading.local()
        self._neutral: NDArray[np.float64] | None = None
        self._rest: NDArray[np.float64] | None = None

    @classmethod
    def load(
        cls,
        urdf: Urdf,
        *,
        floating: bool = False,
        spec: RobotSpec | None = None,
        strict: bool = True,
        gate: Callable[[Urdf], None] | None = None,
    ) -> Robot:
        """The one loader: a parsed URDF's robot, its mimic couplings and tool point.

        `floating`: the root on a free-flyer joint. `spec`: its `arm.tool` is the tool
        point. `strict` refuses (InputError) what Pinocchio would silently accept, such
        as mass="nan" read as 0, and a document its parser reports an error in: what
        simulates, plans or tunes must be sound; `check` loads with strict=False and
        reports those as findings. `gate` may refuse the document first (check's errors).
        ModelLoadError when Pinocchio refuses the URDF.
        """
        if strict:
            loaded = checked_model(urdf, gate=gate, floating=floating)
        else:
            loaded = load_model(urdf.source, xml=urdf_text(urdf), floating=floating)
        return cls(
            loaded.model,
            mimics=mimics(urdf.joints),
            tool=tool_point(urdf, spec),
            source=urdf.source,
            xml=urdf_text(urdf),
            urdf=urdf,
            parser_messages=loaded.parser_messages,
        )

    def _like(self, model: Any) -> Robot:
        """This robot over another model (a reduced, scaled or loaded copy)."""
        return Robot(
            model,
            mimics=self.mimics,
            tool=self.tool,
            source=self.source,
            xml=self.xml,
            urdf=self.urdf,
            parser_messages=self.parser_messages,
        )

    @property
    def data(self) -> Any:
        """A pinocchio.Data for the model, one per thread, shared by this handle's users."""
        data = getattr(self._local, "data", None)
        if data is None:
            data = self._local.data = self.model.createData()
        return data

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

    def rest(self, joint: str) -> float:
        """Where `joint` sits when nobody sets it [rad or m] (`robot.joints.rest`'s rule)."""
        return self.joint(joint).rest

    def neutral(self) -> NDArray[np.float64]:
        """Pinocchio's neutral configuration (every joint at 0, the free-flyer at identity)."""
        if self._neutral is None:
            import pinocchio as pin

            self._neutral = np.asarray(pin.neutral(self.model), dtype=float)
        return self._neutral.copy()

    def rest_q(self) -> NDArray[np.float64]:
        """The rest configuration: every 1-DoF joint at `rest`, the free-flyer at identity."""
        if self._rest is None:
            q = self.neutral()
            for j in self.joints:
                put(q, j, j.rest)
            self._rest = q
        return self._rest.copy()

    def follow(self, values: Mapping[str, float]) -> dict[str, float]:
        """`values` with every mimic follower of a given leader set from it."""
        return follow(self.mimics, values)

    def q(
        self,
        values: Mapping[str, float] | ArrayLike | None = None,
        *,
        joints: Sequence[Joint] | None = None,
        base: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """The configuration with joints set to `values` [rad or m]; the rest from `base`.

        `values` is a mapping by joint name (names that are not 1-DoF joints of the model
        are ignored) or a sequence aligned with `joints` (default: every joint, tree
        order); None sets none. `base` defaults to the rest configuration (`rest_q`: an
        unset joint rests).
        Mimic followers are not moved here: `follow` the values first.
        """
        q = self.rest_q() if base is None else np.array(base, dtype=float)
        if values is None:
            return q
        if isinstance(values, Mapping):
            pairs: Iterable[tuple[Joint, Any]] = (
                (self._by_name[n], x) for n, x in values.items() if n in self._by_name
            )
        else:
            chosen = self.joints if joints is None else joints
            pairs = zip(chosen, np.asarray(values, dtype=float).reshape(-1), strict=True)
        for j, x in pairs:
            put(q, j, float(x))
        return q

    def joint_map(self, joints: Sequence[str], rest: Mapping[str, float] | None = None) -> JointMap:
        """`x` (values of `joints`, in order) -> q, vectorised: for a caller building q per state.

        A planner's validity check calls it per state. Other joints at `rest` (else at
        their own rest), followers following their leaders: the same q as `q(follow(...))`.
        """
        rest = {**{j.name: j.rest for j in self.joints}, **(rest or {})}
        chosen = [self.joint(n) for n in joints]
        template = self.q(self.follow({**rest, **{j.name: 0.0 for j in chosen}}))

        def indices(continuous: bool) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
            pairs = [(j.idx_q, k) for k, j in enumerate(chosen) if j.continuous == continuous]
            table = np.array(pairs, dtype=np.int64).reshape(-1, 2)
            return table[:, 0].copy(), table[:, 1].copy()

        (lq, lx), (cq, cx) = indices(False), indices(True)
        by_name = self._by_name
        followers = tuple(
            (
                by_name[m.follower].idx_q,
                by_name[m.follower].continuous,
                m.follower,
                m.leader,
                m.multiplier,
                m.offset,
            )
            for m in self.mimics
            if m.follower in by_name
        )
        return JointMap(template, (lq, lx), (cq, cq + 1, cx), followers, tuple(joints), rest)

    def reduced(self, joints: Sequence[str]) -> Robot:
        """The robot with only `joints` movable; the others locked where they rest (`rest`).

        InputError (field `joints`) for an unknown joint or one listed twice.
        """
        names = list(self.model.names)[1:]
        for name in joints:
            if name not in names:
                raise InputError(
                    f"unknown joint {name!r}; valid: {', '.join(names)}", field="joints"
                )
        if len(set(joints)) != len(joints):
            raise InputError("a joint is listed twice", field="joints")
        lock = [self.model.getJointId(nm) for nm in names if nm not in joints]
        if not lock:
            return self
        return self._like(reduced_model(self.model, lock, self.rest_q()))

    def with_limits(self, **arrays: ArrayLike) -> Robot:
        """A copy with some limit arrays replaced (names of `LIMITS`, one value per joint).

        A continuous joint keeps its infinite range; an effort <= 0 or not finite is read
        back as inf (no limit), as from a URDF.
        """
        model = self.model.copy()
        vectors = {
            "lower": (model.lowerPositionLimit, True),
            "effort": (model.effortLimit, False),
            "upper": (model.upperPositionLimit, True),
            "damping": (model.damping, False),
            "velocity": (model.velocityLimit, False),
            "friction": (model.friction, False),
        }
        for name, values in arrays.items():
            if name not in vectors:
                raise ValueError(f"unknown limit {name!r}; valid: {', '.join(LIMITS)}")
            vec, in_q = vectors[name]
            for j, x in zip(self.joints, np.asarray(values, dtype=float), strict=True):
                if not in_q:
                    vec[j.idx_v] = x
                elif not j.continuous:  # a continuous joint has no range to set
                    vec[j.idx_q] = x
        return self._like(model)

    def scaled(self, mass: Sequence[float], friction: Sequence[float]) -> Robot:
        """A copy with the bodies' masses and inertias and the joints' friction scaled.

        `mass`: a factor per body in model order (same centre of mass); `friction`: one
        per joint of `joints`.
        """
        import pinocchio as pin

        model = self.model.copy()
        for i, s in enumerate(mass, start=1):
            Y = model.inertias[i]
            model.inertias[i] = pin.Inertia(Y.mass * s, Y.lever.copy(), Y.inertia * s)
        for j, s in zip(self.joints, friction, strict=True):
            model.friction[j.idx_v] = j.friction * s
        return self._like(model)

    def with_point_mass(self, link: str, xyz: ArrayLike, mass: float) -> Robot:
        """A copy with a point mass [kg] at `xyz` [m] in `link`'s frame added to its body."""
        import pinocchio as pin

        model = pin.Model(self.model)
        frame = model.frames[self.frame(link)]
        point = frame.placement.act(np.asarray(xyz, dtype=float))
        jid = frame.parentJoint
        model.inertias[jid] = model.inertias[jid] + pin.Inertia(mass, point, np.zeros((3, 3)))
        return self._like(model)

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
        return collision_model(self.model, text, self.source)
