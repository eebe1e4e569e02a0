"""The course robot with sensors, driven by /cmd_vel commands: the drive-level tests' runs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from armcli.drive import job as drive
from armcli.sim.options import SimOptions
from tests.helpers import DEFAULT_SPEC, spec_file


def course_with(tmp_path: Path, sensors: dict[str, Any], caster_mu: float | None = None) -> Path:
    """The course spec with `sensors` (and the caster's Gazebo mu, if given)."""
    text = DEFAULT_SPEC.read_text()
    if caster_mu is not None:
        text = text.replace("contact: {mu1: 0.1, mu2: 0.1}",
                            f"contact: {{mu1: {caster_mu}, mu2: {caster_mu}}}")  # fmt: skip
    path = tmp_path / "robot.yaml"
    path.write_text(text + "\n" + yaml.safe_dump({"sensors": sensors}))
    return path


def run(spec: Path, commands: str, duration: float, world: str | None = None) -> drive.DriveRun:
    """Drive `spec` by the /cmd_vel `commands` (YAML text) among `world`'s objects."""
    cmd = spec.parent / "cmd.yaml"
    cmd.write_text(commands)
    scene = None
    if world is not None:
        scene = spec.parent / "world.yaml"
        scene.write_text(world)
    job = drive.prepare(spec_file(spec), SimOptions(duration=duration), cmd, world=scene)
    return drive.run(job)


def reading(run_: drive.DriveRun, name: str) -> Any:
    """The reading of sensor `name`."""
    return next(r for r in run_.readings if r.name == name)
