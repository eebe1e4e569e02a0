"""Whether a run tipped the robot over: one verdict type for both engines.

The fixed-base run judges the zero-moment point against the support polygon
(sim.tipping's `ZmpReport`, its excursions from analysis.excursion); the MuJoCo drive
judges the base's tilt against each edge's tipping angle (analysis.liftoff's
`TiltVerdict`). Their numbers differ, what a caller does with them does not: print the
warnings (what lifted off, what rocked back), print the summary line, and end with the
error when the robot tipped.
"""

from __future__ import annotations

from typing import Protocol

from armcli.errors import TipOverError


class TipVerdict(Protocol):
    """A run's tip-over verdict, whichever engine judged it."""

    @property
    def tips(self) -> bool:
        """Whether the robot tipped over (the run then ends with `error()`)."""
        ...

    def line(self) -> str:
        """The summary's line: the closest the run came to tipping, and whether it did."""
        ...

    def notes(self) -> list[str]:
        """Warnings: what lifted off or rocked back without tipping the robot."""
        ...

    def error(self) -> TipOverError:
        """What a run that tipped ends with (after its files are written)."""
        ...
