"""One exception hierarchy; the CLI maps `exit_code` to the process exit status.

Exit codes: 2 = the input cannot be used (bad file, refused xacro, bad option),
1 = the run worked but its verdict is negative (error findings, stale build,
diverged simulation). Library code raises these and never prints or exits.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_UNUSABLE = 2


EXPANDED_TAG = "#expanded"  # source suffix of a xacro file's expansion (robot_source)


def split_source(source: str) -> tuple[str, str]:
    """(file, part) of a document's source name; part is "" for a whole file.

    `robot.yaml#arm.urdf` (a URDF built in memory from a spec) and `x.xacro#expanded`
    name a part of a file; any other `#` belongs to the file name (`a#b.urdf` is a file).
    """
    path, sep, part = source.rpartition("#")
    spec_part = path.endswith((".yaml", ".yml")) and part.endswith(".urdf") and "/" not in part
    if sep and (f"#{part}" == EXPANDED_TAG or spec_part) and not os.path.lexists(source):
        return path, part
    return source, ""


def _where(file: str | Path | None, line: int | None) -> str:
    if file is None:
        return ""
    text = str(file)
    if line and text.endswith(EXPANDED_TAG):  # the line is in the expansion, not the xacro
        return f"{text[: -len(EXPANDED_TAG)]} (line {line} of its xacro expansion)"
    return f"{text}:{line}" if line else text


class ArmcliError(Exception):
    """Base of every error armcli raises on purpose."""

    exit_code: int = EXIT_UNUSABLE
    #: What the CLI writes before each line; None when the lines carry their own label.
    label: str | None = "error"
    #: The command wrote its result document before raising (check's report): with
    #: `--format json` the CLI adds no error document of its own to stdout.
    reported: bool = False

    def lines(self) -> list[str]:
        """The one-line-per-problem rendering the CLI prints."""
        return [str(self)]


class InputError(ArmcliError):
    """A file or value the user gave cannot be used."""

    def __init__(
        self,
        message: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        field: str | None = None,
    ) -> None:
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.field = field
        super().__init__(_text(self.file, line, field, message))

    def renamed(self, names: Mapping[str, str]) -> InputError:
        """This error in another vocabulary: the CLI's flags for the library's names.

        Library errors name what a Python caller passed (`SimOptions.dt`); `names` maps
        such a name to a flag (`--dt`) in the field, the file label and wherever the
        message quotes it in backticks. Returns self when nothing is renamed.
        """

        def flag(m: re.Match[str]) -> str:
            return names.get(m[1], m[0])

        message = _QUOTED_NAME.sub(flag, self.message)
        field = names.get(self.field, self.field) if self.field else None
        file = names.get(self.file, self.file) if self.file else None
        if (message, field, file) == (self.message, self.field, self.file):
            return self
        new = type(self).__new__(type(self))  # copy.copy would call a subclass's __init__
        new.__dict__.update(self.__dict__)
        new.message, new.field, new.file = message, field, file
        new.args = (_text(file, self.line, field, message),)
        return new


_QUOTED_NAME = re.compile(r"`([A-Za-z_][A-Za-z0-9_.]*)`")


def _text(file: str | None, line: int | None, field: str | None, message: str) -> str:
    prefix = " ".join(p for p in (_where(file, line), field) if p)
    return f"{prefix}: {message}" if prefix else message


@dataclass(frozen=True)
class Problem:
    """One validation problem: where it is and what is wrong."""

    field: str
    message: str
    line: int | None = None


_VALUES = re.compile(r"'[^']*'|\"[^\"]*\"|[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
_INDICES = re.compile(r"\[\d+\]")


def one_per_kind(problems: Sequence[Problem], extra: Sequence[int] = ()) -> list[Problem]:
    """The first problem of each kind, saying how many more there are (`(and N more)`).

    A kind is the field without its list indices (`commands[*].linear.x`) and the message
    without the values it quotes: 25,000 bad commands are one line, not 25,000 (issue 42).
    `extra`: repeats already counted per problem (a reader's own `once`).
    """
    counts = [*extra, *([0] * (len(problems) - len(extra)))]
    first: dict[tuple[str, str], int] = {}
    for i, p in enumerate(problems):
        kind = (_INDICES.sub("[*]", p.field), _VALUES.sub("_", p.message))
        if kind in first:
            counts[first[kind]] += 1 + counts[i]
        else:
            first[kind] = i
    out = []
    for i in first.values():
        p = problems[i]
        out.append(
            Problem(p.field, f"{p.message} (and {counts[i]} more)", p.line) if counts[i] else p
        )
    return out


class SpecError(InputError):
    """A spec (or other structured YAML input) failed validation; one line per problem."""

    def __init__(self, file: str | Path, problems: Sequence[Problem]) -> None:
        self.problems = list(problems)
        first = self.problems[0] if self.problems else Problem("", "invalid")
        super().__init__(first.message, file=file, line=first.line, field=first.field or None)

    def lines(self) -> list[str]:
        """One line per problem, each prefixed with its file:line and field path."""
        out = []
        for p in self.problems:
            where = _where(self.file, p.line)
            head = " ".join(x for x in (where, p.field) if x)
            out.append(f"{head}: {p.message}" if head else p.message)
        return out


class UnstableLoopError(InputError):
    """The PD gains diverge at the time step (armcli.analysis.verdict); carries the one remedy.

    The library names no option: the command layer says where dt and the gains came from
    (`located`).
    """

    def __init__(
        self,
        message: str,
        *,
        scheme: str,
        dt: float,
        suggestion_dt: float,
        kp: Sequence[float] | None,
        kd: Sequence[float] | None,
        file: str | Path | None = None,
        field: str | None = None,
    ) -> None:
        self.scheme, self.dt, self.suggestion_dt = scheme, dt, suggestion_dt
        self.kp = tuple(kp) if kp is not None else None
        self.kd = tuple(kd) if kd is not None else None
        super().__init__(message, file=file, field=field)

    def located(self, *, file: str | Path | None, field: str | None) -> UnstableLoopError:
        """The same error, saying which file and field (or option) dt and gains came from."""
        return UnstableLoopError(
            self.message,
            scheme=self.scheme,
            dt=self.dt,
            suggestion_dt=self.suggestion_dt,
            kp=self.kp,
            kd=self.kd,
            file=file,
            field=field,
        )


class XacroRefusedError(InputError):
    """A foreign xacro file would run code from the file; refused without --trust-xacro."""


class OutputRefusedError(InputError):
    """An output path armcli will not write (root, home, foreign non-empty directory, ...)."""


@dataclass(frozen=True)
class RuleViolation:
    """An error finding of `check` (rule id, where, what) carried by ModelRefusedError."""

    rule: str
    file: str
    line: int | None
    message: str


class ModelRefusedError(InputError):
    """`check` reports errors for a model another command was asked to use; one line each.

    `remedy`, set by the command layer, says how to go on anyway (e.g. which option).
    """

    def __init__(
        self, source: str, violations: Sequence[RuleViolation], remedy: str | None = None
    ) -> None:
        self.source = source
        self.violations = list(violations)
        self.remedy = remedy
        first = self.violations[0]
        super().__init__(f"[{first.rule}] {first.message}", file=first.file, line=first.line)

    def rules(self) -> list[str]:
        """The refusing rule ids, each once, in order."""
        return list(dict.fromkeys(v.rule for v in self.violations))

    def lines(self) -> list[str]:
        """One line per violation, then one saying the model is refused (and the remedy)."""
        out = [f"{_where(v.file, v.line)}: [{v.rule}] {v.message}" for v in self.violations]
        n = len(self.violations)
        last = f"{self.source}: `armcli check` reports {n} error(s); the model is refused"
        out.append(f"{last}; {self.remedy}" if self.remedy else last)
        return out


class ModelLoadError(InputError):
    """Pinocchio refused the URDF; carries what its parser printed."""

    def __init__(self, message: str, *, file: str, parser_messages: list[str]) -> None:
        self.parser_messages = parser_messages
        super().__init__(message, file=file)


class UnusableInputsError(ArmcliError):
    """One or more inputs could not be used: one line each, exit 2, after the others' report."""

    exit_code = EXIT_UNUSABLE

    def __init__(self, errors: Sequence[ArmcliError]) -> None:
        self.errors = list(errors)
        super().__init__(str(self.errors[0]))

    def lines(self) -> list[str]:
        """The lines of every unusable input, in the order they failed."""
        return [line for e in self.errors for line in e.lines()]


class BuildError(ArmcliError):
    """Generating or expanding robot description files failed."""


class StaleBuildError(ArmcliError):
    """`build --check`: committed outputs differ from a fresh build."""

    exit_code = EXIT_FAILED
    label = None

    def __init__(self, stale: Sequence[str]) -> None:
        self.stale = list(stale)
        super().__init__("stale generated files: " + ", ".join(self.stale))

    def lines(self) -> list[str]:
        """One `stale:` line per file, then a count and how to fix it."""
        return [f"stale: {s}" for s in self.stale] + [
            f"{len(self.stale)} generated file(s) differ from a fresh build; run `armcli build`"
        ]


class FindingsError(ArmcliError):
    """`check` found problems of error severity (raised after its report is written).

    `unusable` are files it could not read (inside a directory, next to usable ones),
    printed one line each before the total.
    """

    exit_code = EXIT_FAILED
    reported = True

    def __init__(self, message: str, unusable: Sequence[ArmcliError] = ()) -> None:
        self.unusable = list(unusable)
        super().__init__(message)

    def lines(self) -> list[str]:
        """The unusable files' lines, then the total."""
        return [*(line for e in self.unusable for line in e.lines()), str(self)]


class SimulationError(ArmcliError):
    """A simulation became non-finite or unphysical; carries the evidence."""

    exit_code = EXIT_FAILED

    def __init__(
        self,
        message: str,
        *,
        time: float | None = None,
        step: int | None = None,
        joint: str | None = None,
        cause: str | None = None,
    ) -> None:
        self.time = time
        self.step = step
        self.joint = joint
        self.cause = cause
        parts = [message]
        if time is not None:
            parts.append(f"at t = {time:.4f} s")
        if step is not None:
            parts.append(f"(step {step})")
        if joint is not None:
            parts.append(f"joint {joint}")
        text = " ".join(parts)
        if cause:
            text += f"; likely cause: {cause}"
        super().__init__(text)


class TipOverError(ArmcliError):
    """The simulated motion tips the robot over: its zero-moment point left the support polygon.

    Raised after the run's files and summary are written; carries the evidence.
    """

    exit_code = EXIT_FAILED

    def __init__(self, message: str, *, time: float, margin: float, case: str) -> None:
        self.time = time
        self.margin = margin  # [m] negative: how far outside
        self.case = case
        super().__init__(message)


class ExportRefusedError(ArmcliError):
    """An export would write a model its target simulator refuses: which part, and why."""

    exit_code = EXIT_FAILED

    def __init__(self, file: str | Path, reason: str, *, link: str | None = None) -> None:
        self.file = str(file)
        self.link = link
        self.reason = reason
        what = f"link {link!r}: " if link is not None else ""
        super().__init__(f"{_where(file, None)}: {what}{reason}")


class NoSpecError(InputError):
    """No spec argument and none found in the current directory; says what to run."""


class ExistingFileError(InputError):
    """A file `armcli init` would write already exists; nothing was written."""


class PlanningError(ArmcliError):
    """No certified motion: start or goal in collision, goal out of limits, no IK, no path.

    `kind` names the failure (`start-collision`, `goal-collision`, `goal-limits`, `ik`,
    `no-path`, `certify`); `pair` the two colliding bodies when there are some.
    """

    exit_code = EXIT_FAILED

    def __init__(self, kind: str, message: str, *, pair: tuple[str, str] | None = None) -> None:
        self.kind = kind
        self.pair = pair
        self.reason = message
        super().__init__(message)


class ArmcliWarning(UserWarning):
    """Something the user should know that does not stop the command (a line `warning: ...`).

    Library code warns with `warnings.warn(text, ArmcliWarning)`; the CLI prints each as one
    escaped line on stderr (cli.main), so a library never prints.
    """
