"""`armcli init`: a first project (spec, trajectories, README) from the shipped examples.

The example specs live once, in the package (`armcli/examples/`, which the repository's
`specs/` links to), so a user who installed the wheel gets exactly the robots the
repository tests. The spec is written as `armcli.yaml`, the name `find_spec` looks for
first, so every command then runs without arguments; trajectories go to `trajectories/`
beside it (they name joints, not files, so nothing inside needs rewriting).
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from string import Template

from armcli.defaults import SPEC_FILE, TRAJECTORY_DIR
from armcli.errors import InputError
from armcli.io.newfiles import create_files

README = "README.md"


@dataclass(frozen=True)
class ExampleTemplate:
    """One example project: where its files are in `armcli/examples/`, what it is."""

    spec: str  # spec file under examples/; its stem is the spec's `name`
    trajectories: str  # directory under examples/ with this robot's trajectories
    pose: str  # a named pose of the spec, for the README's render command
    about: str  # one sentence for the README
    extras: str | None = None  # directory under examples/ whose files go beside the spec
    more: str = ""  # more README lines (commands the template is for)


TEMPLATES = {
    "course": ExampleTemplate(
        spec="my_robot.yaml",
        trajectories="trajectories",
        pose="reach",
        about="the ROS 2 for Beginners course robot: a 2-axis arm on a differential-drive base.",
    ),
    "rover": ExampleTemplate(
        spec="rover.yaml",
        trajectories="trajectories/rover",
        pose="reach",
        about="the course robot with a 2-D lidar, a depth camera and an IMU, and a world of "
        "boxes to drive it through (world.yaml; Foxglove: foxglove_layout.json).",
        extras="rover",
        more=(
            "\nDrive it among the boxes with its sensors on, then replay the run (scans and "
            "point clouds drawn)\nor open run.mcap in Foxglove with foxglove_layout.json:\n\n"
            "```bash\narmcli simulate --cmd-vel trajectories/drive.yaml --world world.yaml "
            "-o run.mcap --plot drive.png\narmcli view --replay run.mcap\n```\n"
        ),
    ),
    "tabletop": ExampleTemplate(
        spec="tabletop_arm.yaml",
        trajectories="trajectories/tabletop_arm",
        pose="ready",
        about="a 3-axis tabletop arm (yaw, shoulder, elbow) without a mobile base.",
    ),
}
DEFAULT_TEMPLATE = "course"


def _template(name: str) -> ExampleTemplate:
    if name not in TEMPLATES:
        known = ", ".join(TEMPLATES)
        raise InputError(f"unknown template {name!r}; known: {known}", field="template")
    return TEMPLATES[name]


def template_files(name: str) -> dict[str, bytes]:
    """Relative path -> content of everything `armcli init --template NAME` writes."""
    t = _template(name)
    examples = resources.files("armcli").joinpath("examples")
    files = {SPEC_FILE.as_posix(): examples.joinpath(t.spec).read_bytes()}
    trajectories = sorted(
        (f for f in examples.joinpath(t.trajectories).iterdir() if f.name.endswith(".yaml")),
        key=lambda f: f.name,
    )
    for f in trajectories:
        files[(TRAJECTORY_DIR / f.name).as_posix()] = f.read_bytes()
    if t.extras is not None:
        for f in sorted(examples.joinpath(t.extras).iterdir(), key=lambda f: f.name):
            files[f.name] = f.read_bytes()
    readme = Template(resources.files("armcli").joinpath("data", "init_readme.md.tmpl").read_text())
    files[README] = readme.substitute(
        name=Path(t.spec).stem,
        about=t.about,
        template=name,
        spec=SPEC_FILE.as_posix(),
        pose=t.pose,
        pick=(TRAJECTORY_DIR / "pick.yaml").as_posix(),
        trajectories=", ".join(_listed(f.name, f.read_text("utf-8")) for f in trajectories),
        more=t.more,
    ).encode("utf-8")
    return files


def _listed(name: str, text: str) -> str:
    """How the README lists an example: a /cmd_vel command file says what it is for."""
    path = f"`{(TRAJECTORY_DIR / name).as_posix()}`"
    return f"{path} (/cmd_vel commands for `simulate --cmd-vel`)" if "\ncommands:" in text else path


def init_project(directory: str | Path, template: str = DEFAULT_TEMPLATE) -> list[Path]:
    """Write the example project into `directory` (created if missing), all or nothing.

    Raises:
        ExistingFileError: one of the files already exists; nothing was written.
        InputError: unknown template.
    """
    return create_files(directory, template_files(template))
