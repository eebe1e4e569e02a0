"""One planning query with roboplan 0.7.0's Python API, as a process: the peer of `armcli plan`.

python bench/roboplan_query.py SCENE.yaml START GOAL OUT
(START and GOAL: seven comma-separated joint values of the Panda's arm.) Loads the Panda's
URDF and SRDF, adds the scene's primitives (read with PyYAML), plans with RRT-Connect,
shortcuts, times the path with roboplan's TOPP-RA and writes the trajectory's points: the
same steps `armcli plan` takes (it also certifies). bench/bench_plan.py measures both
processes' CPU time.
"""

from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

import numpy as np
import yaml

ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data"
PANDA = ERD / "robots" / "panda_description"
ARM = [f"panda_joint{i}" for i in range(1, 8)]
STEP = 0.02  # [rad]


def pose(p: dict | None) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    p = p or {}
    T = np.eye(4)
    T[:3, 3] = [float((p.get("position") or {}).get(k, 0.0)) for k in "xyz"]
    o = p.get("orientation") or {}
    T[:3, :3] = Rotation.from_quat([float(o.get(k, 0.0 if k != "w" else 1.0)) for k in "xyzw"]
                                   ).as_matrix()  # fmt: skip
    return T


def main() -> None:
    from roboplan.core import (
        Box,
        Cylinder,
        JointConfiguration,
        PathShortcutter,
        PathShortcuttingOptions,
        Scene,
        Sphere,
        loadUrdfSceneDescription,  # fmt: skip
    )
    from roboplan.rrt import RRT, RRTOptions
    from roboplan.toppra import PathParameterizerTOPPRA

    scene_file, start, goal, out = sys.argv[1:5]
    scene = Scene("panda", loadUrdfSceneDescription(str(PANDA / "urdf" / "panda.urdf"),
                                                     [str(ERD.parent)]))  # fmt: skip
    scene.importSrdf((PANDA / "srdf" / "panda.srdf").read_text())
    scene.addGroup("arm", ARM)
    doc = yaml.safe_load(Path(scene_file).read_text())
    make = {"box": lambda d: Box(*d), "sphere": lambda d: Sphere(d[0]),
            "cylinder": lambda d: Cylinder(d[1], d[0])}  # fmt: skip
    names = []
    for obj in doc["world"]["collision_objects"]:
        T_obj = pose(obj.get("pose"))
        for k, (prim, p) in enumerate(zip(obj["primitives"], obj["primitive_poses"], strict=True)):
            name = f"{obj['id']}_{k}"
            getattr(scene, f"add{prim['type'].capitalize()}Geometry")(
                name, "universe", make[prim["type"]](prim["dimensions"]),
                np.asfortranarray(T_obj @ pose(p)), np.array([0.5, 0.5, 0.5, 1.0]))  # fmt: skip
            names.append(name)
    scene.setCollisions([(a, b) for i, a in enumerate(names) for b in names[i + 1 :]], False)
    rrt = RRT(scene, RRTOptions(group_name="arm", rrt_connect=True, max_planning_time=1.0,
                                max_nodes=100000, collision_check_step_size=STEP))  # fmt: skip
    a = np.array([float(v) for v in start.split(",")])
    b = np.array([float(v) for v in goal.split(",")])
    path = rrt.plan(JointConfiguration(ARM, a), JointConfiguration(ARM, b))
    path = PathShortcutter(scene, PathShortcuttingOptions(group_name="arm", max_step_size=STEP)
                           ).shortcut(path)  # fmt: skip
    traj = PathParameterizerTOPPRA(scene, "arm").generate(path)
    with open(out, "w") as fh:
        for t, q in zip(traj.times, traj.positions, strict=True):
            fh.write(f"{t!r} " + " ".join(repr(float(v)) for v in q) + "\n")


if __name__ == "__main__":
    main()
