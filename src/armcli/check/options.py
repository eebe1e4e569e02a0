"""What a `check` run is asked: `CheckOptions` (spec, gains, meshes) and tip-over options."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile, lookup_for

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec


@dataclass(frozen=True)
class TipoverOptions:
    """Balance and reach options (check/tipover.py, check/zmp.py, check/reach.py)."""

    payload: float = 0.0  # [kg] point mass at the payload point
    payload_link: str | None = None  # its link (at the origin); default: the tool point
    contact_links: tuple[str, ...] | None = None  # default: found from the geometry
    min_margin: float = 0.02  # [m] margin below which `support-margin` warns
    trajectory: Path | None = None  # simulate it and report the zero-moment point
    base_accel: float | None = None  # [m/s²] default: the diff-drive plugin's
    reach_points: tuple[tuple[float, float, float], ...] = ()  # [m] in the root frame


@dataclass(frozen=True)
class CheckOptions:
    """What the rules may use beyond the URDF itself."""

    spec: RobotSpec | None = None
    package_dirs: Mapping[str, Path] = field(default_factory=dict)
    search_paths: tuple[Path, ...] = ()
    tipover: TipoverOptions = field(default_factory=TipoverOptions)
    ros_distro: str | None = None  # `--distro` for ROS packages (default: from their plugins)
    robot_file: RobotFile | None = None  # the documents' file: its Robots are built once

    def mesh_search(self) -> MeshSearch:
        """The mesh-resolver view of these options (shared with view and render)."""
        return lookup_for(self.spec, MeshSearch(self.package_dirs, self.search_paths))
