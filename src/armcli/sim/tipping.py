"""Will the robot tip over while its arm runs a trajectory? `simulate`'s balance report.

From a prepared simulation (`sim.job`): the whole robot standing on its contacts
(`analysis.stance`: the spec's full URDF, or a given URDF whose wheels touch the ground),
the steps the run must keep for the zero-moment point (`analysis.zmp`), and after the run
the series, its worst moment, the states-file columns and the summary line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from armcli.analysis import zmp as zmps
from armcli.analysis.excursion import Excursion, excursions
from armcli.analysis.ground import mesh_loader
from armcli.analysis.stance import NoStance, Payload, Stance, stance_of
from armcli.errors import InputError, TipOverError
from armcli.robot.file import floating_of
from armcli.robot.tool import tool_point
from armcli.sim.job import SimJob
from armcli.sim.simulate import SimResult
from armcli.sim.states import sample_steps
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile, lookup_for

if TYPE_CHECKING:
    pass

DEFAULT_MIN_MARGIN = 0.02  # [m] as `check`'s support-margin threshold
COLUMNS = ("zmp.x", "zmp.y", "zmp.margin", "zmp.margin_base")


@dataclass(frozen=True)
class TipOptions:
    """Balance options of a run (None: from the spec, the URDF or the default)."""

    base_accel: float | None = None  # [m/s²] the base's acceleration and braking
    payload: float = 0.0  # [kg]
    payload_link: str | None = None  # default: the tool point
    contact_links: tuple[str, ...] | None = None
    min_margin: float = DEFAULT_MIN_MARGIN  # [m]

    def __post_init__(self) -> None:
        for name in ("payload", "min_margin"):
            x = getattr(self, name)
            if not (math.isfinite(x) and x >= 0):
                raise InputError(f"must be finite and >= 0, got {x:g}", field=f"TipOptions.{name}")
        if self.base_accel is not None and not (
            math.isfinite(self.base_accel) and self.base_accel >= 0
        ):
            raise InputError(
                f"must be finite and >= 0, got {self.base_accel:g}", field="TipOptions.base_accel"
            )


@dataclass(frozen=True)
class Tipping:
    """What a run needs to report its zero-moment point: the stance and the base's acceleration."""

    stance: Stance
    base_accel: float  # [m/s²]
    accel_source: str  # where it came from, for the summary
    threshold: float  # [m]

    def steps(self, job: SimJob, steps: int) -> NDArray[np.int64]:
        """The steps to keep: pairs for the acceleration, the output rate's among them."""
        return zmps.zmp_steps(steps, sample_steps(steps, job.config.dt, job.rate))

    def series(self, job: SimJob, res: SimResult) -> zmps.ZmpSeries:
        """The zero-moment point at every kept state of the run."""
        return zmps.zmp_series(
            self.stance,
            res.joint_names,
            res.t,
            res.step,
            res.q,
            res.v,
            res.dt,
            self.base_accel,
            self.threshold,
            zmps.impacts(res.stop_active, res.v),
        )


def whole_robot(file: RobotFile) -> Urdf:
    """The robot whose balance a fixed-base run reports.

    A spec's whole robot when it mounts the arm on a base (also for a URDF file run with
    that spec's settings, `RobotFile.with_spec`), else what is simulated (`file.arm`).
    """
    spec = file.spec
    if spec is None or spec.mounted_base() is None:
        return file.arm
    if file.compiled:
        return file.robot
    whole = file.document(f"{spec.name}.urdf") if file.arm.source.endswith(".urdf") else None
    return whole if whole is not None else file.arm


def prepare(
    file: RobotFile, job: SimJob, opts: TipOptions, search: MeshSearch, notes: list[str]
) -> Tipping | None:
    """The run's balance set-up, or None (with a note) for a robot on a fixed base.

    The robot stands on `whole_robot(file)`'s floating `Robot`, the one `check`'s
    static balance stands on (`robot_of`: built once per file).
    """
    urdf, spec = whole_robot(file), file.spec
    base = spec.mounted_base() if spec is not None else None
    candidates = set(base.links) if base is not None and opts.contact_links is None else None
    point = tool_point(urdf, spec)
    if opts.payload_link is not None:
        payload = Payload(opts.payload, opts.payload_link)
    elif point is not None:
        payload = Payload(opts.payload, point.link, point.xyz)
    else:
        return None
    missing: list[str] = []
    search = lookup_for(spec, search)  # the packages the spec records too
    found = stance_of(
        urdf,
        candidates=candidates,
        declared=opts.contact_links,
        mesh=mesh_loader(urdf, search, missing),
        payload=payload,
        floating=floating_of(file, urdf),
    )
    if isinstance(found, NoStance):
        notes.append(f"no zero-moment point: {found.reason}")
        return None
    missing_joints = [n for n in job.robot.names if not found.model.existJointName(n)]
    if missing_joints:
        notes.append(f"no zero-moment point: {', '.join(missing_joints)} not in {urdf.source}")
        return None
    accel, source = base_acceleration(opts, urdf, plugin_default=False)
    return Tipping(found, accel, source, opts.min_margin)


def base_acceleration(
    opts: TipOptions, urdf: Urdf, plugin_default: bool = True
) -> tuple[float, str]:
    """The base's acceleration: the option's, else a base at rest or the plugin's limit.

    `simulate` assumes no acceleration nobody asked for; `check --trajectory` keeps its
    worst case (`plugin_default`): the diff-drive plugin's max_wheel_acceleration.
    """
    if opts.base_accel is not None:
        return opts.base_accel, "--base-accel"
    if not plugin_default:
        return 0.0, "a base at rest (--base-accel adds one)"
    limit = zmps.drive_acceleration(urdf)
    if limit is not None:
        return limit, "the diff-drive plugin's max_wheel_acceleration"
    return 0.0, "no diff-drive acceleration limit in the URDF (give --base-accel)"


def columns(series: zmps.ZmpSeries, res: SimResult, rate: float) -> dict[str, NDArray[Any]]:
    """States-file columns at the output rate: the point, its margin, the worst with the base.

    A state the series left out (a joint-stop impact: an impulse, no finite acceleration)
    gets NaN in these columns rather than a made-up point.
    """
    want = sample_steps(res.steps, res.dt, rate)
    rows = np.minimum(np.searchsorted(series.step, want), max(len(series.step) - 1, 0))
    known = series.step[rows] == want if len(series.step) else np.zeros(len(want), dtype=bool)

    def pick(values: NDArray[Any]) -> NDArray[Any]:
        return (
            np.where(known, values[rows], np.nan)
            if len(series.step)
            else np.full(len(want), np.nan)
        )

    return {
        COLUMNS[0]: pick(series.zmp[:, 0, 0]),
        COLUMNS[1]: pick(series.zmp[:, 0, 1]),
        COLUMNS[2]: pick(series.margin[:, 0]),
        COLUMNS[3]: pick(np.min(series.margin[:, 1:], axis=1)),
    }


@dataclass(frozen=True)
class ZmpReport:
    """A run's zero-moment point in numbers: its worst moment and what still holds."""

    base_accel: float  # [m/s²] of the accelerating and braking cases
    accel_source: str
    payload: str | None
    threshold: float  # [m]
    min_margin: float  # [m] over the run and the cases (negative: it tips)
    time: float  # [s] when
    case: zmps.Case
    direction: str  # toward which edge
    zmp: tuple[float, float]  # [m] the point then
    arm_margin: float  # [m] least margin of the arm motion alone (base at rest)
    max_base_accel: float  # [m/s²] the largest that keeps the margin >= 0 at every state
    max_base_accel_margin: float  # [m/s²] the largest that keeps it >= threshold
    impacts: int  # states left out: joint-stop impacts
    excursions: tuple[Excursion, ...] = ()  # the point outside the polygon, interval by interval

    @property
    def tips(self) -> bool:
        """Whether an excursion of the point rotates the robot over a support edge."""
        return any(e.tips for e in self.excursions)

    @property
    def lifts(self) -> tuple[Excursion, ...]:
        """The excursions too short to tip the robot: a wheel lifts off for an instant."""
        return tuple(e for e in self.excursions if not e.tips)

    @property
    def when(self) -> str:
        """The worst moment's case, with the base's acceleration when it counts."""
        return self.case + (f" at {self.base_accel:g} m/s²" if self.case != zmps.CASES[0] else "")

    def line(self) -> str:
        """The summary's line: where the point came closest to the edge, and whether it tips."""
        load = f", {self.payload}" if self.payload else ""
        head = (
            f"zero-moment point (base held on its wheels{load}; base accel "
            f"{self.base_accel:g} m/s² from {self.accel_source}): "
        )
        if self.tips:
            what = (
                f"TIPS: {-self.min_margin * 1e3:.1f} mm outside the support polygon "
                f"toward {self.direction}"
            )
        elif self.min_margin < 0:
            what = (
                f"{-self.min_margin * 1e3:.1f} mm outside toward {self.direction} for "
                f"{sum(e.duration for e in self.lifts):.3f} s: a wheel lifts off, no tip"
            )
        else:
            what = f"least margin {self.min_margin * 1e3:.1f} mm toward {self.direction}"
        left = f"; {self.impacts} joint-stop impact(s) left out" if self.impacts else ""
        holds = "any" if math.isinf(self.max_base_accel) else f"{self.max_base_accel:.3g} m/s²"
        return (
            f"{head}{what} at t = {self.time:.3f} s ({self.when}); arm motion alone: "
            f"{self.arm_margin * 1e3:.1f} mm; base acceleration that holds: {holds}{left}"
        )

    def notes(self) -> list[str]:
        """The lift-off warnings: excursions too short to tip the robot, case by case."""
        return [e.line() for e in self.lifts]

    def error(self) -> TipOverError:
        """The error a run that tips the robot over ends with (after its files are written)."""
        e = next(e for e in self.excursions if e.tips)
        accel = f" at {self.base_accel:g} m/s²" if e.case != zmps.CASES[0] else ""
        return TipOverError(
            f"the robot tips over: its zero-moment point is up to {e.depth * 1e3:.1f} mm "
            f"outside the support polygon toward {e.direction} from t = {e.start:.3f} s for "
            f"{e.duration:.3f} s ({e.case}{accel}), long enough to rotate it over that edge",
            time=e.start,
            margin=-e.depth,
            case=e.case,
        )


def report(tip: Tipping, series: zmps.ZmpSeries) -> ZmpReport:
    """The numbers of a run's zero-moment point."""
    k, c = series.worst()
    poly = tip.stance.polygon
    p = series.zmp[k, c]
    finite = bool(np.all(np.isfinite(p)))
    payload = tip.stance.payload
    return ZmpReport(
        base_accel=tip.base_accel,
        accel_source=tip.accel_source,
        payload=payload.label if payload is not None and payload.mass > 0 else None,
        threshold=tip.threshold,
        min_margin=float(series.margin[k, c]),
        time=float(series.t[k]),
        case=zmps.CASES[c],
        direction=poly.edges[poly.nearest_edge(p)].direction if finite else "-",
        zmp=(float(p[0]), float(p[1])),
        arm_margin=float(np.min(series.margin[:, 0])),
        max_base_accel=zmps.max_base_accel(series, poly, 0.0),
        max_base_accel_margin=zmps.max_base_accel(series, poly, tip.threshold),
        impacts=series.impacts,
        excursions=excursions(tip.stance, series),
    )


def plot_row(series: zmps.ZmpSeries) -> Any:
    """A drawer of the tracking plot's fourth row: margins per case, and the point itself."""

    def draw(axes: Any) -> None:
        ax = axes[0]
        for c, name in enumerate(zmps.CASES):
            if c and series.base_accel == 0:
                continue
            label = name + (f" ({series.base_accel:g} m/s²)" if c else "")
            ax.plot(series.t, series.margin[:, c] * 1e3, lw=1.2, label=label)
        ax.axhline(series.threshold * 1e3, color="C3", lw=0.8, ls=":", label="warning")
        ax.axhline(0.0, color="k", lw=0.8, label="tips")
        cases = 1 if series.base_accel == 0 else len(zmps.CASES)
        k = int(np.argmin(np.min(series.margin[:, :cases], axis=1)))  # the least moment
        low = float(np.min(series.margin[k, :cases])) * 1e3
        ax.plot(series.t[k], low, "o", color="C3", ms=5, zorder=5)
        ax.annotate(
            f"least {low:.1f} mm at {series.t[k]:.3f} s",
            (series.t[k], low),
            xytext=(8, -4),
            textcoords="offset points",
            fontsize=8,
            color="C3",
        )
        top = float(np.max(series.margin[:, :cases])) * 1e3
        span = top - min(low, 0.0)
        ax.set_ylim(min(low, 0.0) - 0.15 * span, top + 0.6 * span)  # the legend goes on top
        ax.set_ylabel("ZMP margin [mm]")
        ax.set_title("zero-moment point in the support polygon", fontsize=11)
        if len(axes) > 1:
            axes[1].plot(series.t, series.zmp[:, 0, 0] * 1e3, color="C0", lw=1.2, label="x")
            axes[1].plot(series.t, series.zmp[:, 0, 1] * 1e3, color="C1", lw=1.2, label="y")
            axes[1].set_ylabel("ZMP, arm motion [mm]")
        for a in axes[2:]:
            a.set_visible(False)
        for a in axes[:2]:
            a.set_xlabel("time [s]")
            a.grid(True, alpha=0.3)
        ax.legend(loc="upper center", ncol=3, fontsize=7)
        if len(axes) > 1:
            axes[1].legend(loc="best", fontsize=8)

    return draw
