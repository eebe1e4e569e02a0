"""Rule `reach-point` and the summary's reach envelope: where can the tool point go?

The envelope of the tool point over the chain's joint ranges (`analysis.workspace`: sampled
forward kinematics, extremes refined by local search) goes to the summary; each
`--reach-point` is tested by inverse kinematics, and one the arm cannot reach within
REACH_TOL is an error naming how close it gets and where.
"""

from __future__ import annotations

from armcli.analysis.workspace import REACH_TOL, Chain, envelope, reach_point, sample
from armcli.check.context import Context
from armcli.robot.frames import link_frame
from armcli.robot.tool import tool_point


def check(c: Context) -> None:
    """The workspace of the tool point, and the findings for unreachable points."""
    tool = tool_point(c.urdf, c.opts.spec)
    if tool is None or link_frame(c.loaded().model, tool.link) is None:
        return
    if c.stance is not None and tool.link in c.stance.ground.links:
        c.notes.append(
            f"workspace skipped: the tool point {tool.label} touches the ground "
            "(a base without an arm)"
        )
        return
    chain = Chain(c.loaded(), tool)
    if not chain.joints:
        c.notes.append("workspace skipped: no moving joint between the root and the tool point")
        return
    cloud = sample(chain)
    c.reach = envelope(chain, cloud)
    targets = c.opts.tipover.reach_points
    base = c.opts.spec.mounted_base() if c.opts.spec is not None else None
    if targets and base is not None and c.tree.root not in base.links:
        c.notes.append(
            "reach points skipped: they are checked on the whole robot, in its root frame"
        )
        return
    c.reach_points = tuple(reach_point(chain, cloud, t) for t in targets)
    for rp in c.reach_points:
        if rp.reachable:
            continue
        x, y, z = rp.target
        q = ", ".join(f"{n}={v:.4g}" for n, v in rp.q)
        c.out.add(
            "reach-point",
            c.urdf.line,
            f"point ({x:g}, {y:g}, {z:g}) m is out of reach of {tool.label}: the closest it "
            f"gets is {rp.residual * 1e3:.1f} mm away (at {q}; tolerance {REACH_TOL * 1e3:g} mm)",
            target=list(rp.target),
            residual=rp.residual,
            nearest_sample=rp.nearest_sample,
            q=[v for _, v in rp.q],
        )
