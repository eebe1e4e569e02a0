"""Foreign xacro, safe by default: xacro's own machinery with the code execution taken out.

xacro's macros, properties, blocks, includes, conditionals and arguments are
kept (they are xacro's own functions, unchanged); what is replaced is every
place where the file could run code or reach the machine:

- `${...}` is evaluated by xacro_expr's AST whitelist instead of `eval`;
- `$(...)` allows `arg`, `dirname` and `find PKG`, where PKG must be a
  package inside the allowed roots (an ancestor directory of the file whose
  package.xml names PKG, or a ROS_PACKAGE_PATH entry); `env`, `optenv`,
  `eval`, `cwd` and `anon` are refused;
- includes and `load_yaml` read only regular files inside the allowed roots
  (the file's directory, its package, the packages `find` resolved and
  ROS_PACKAGE_PATH), size-capped, with DOCTYPE/entities refused;
- macro calls and wall time are bounded (exponential macro bombs).

A refusal is an XacroRefusedError naming the file and line of the
expression. The expansion runs in xacro_sandbox's resource-limited child
process (`run_safe`), so that memory is bounded too.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from armcli.errors import InputError, XacroRefusedError
from armcli.io.userfile import read_regular
from armcli.io.yaml import loads_yaml
from armcli.urdf.mesh_confine import is_package
from armcli.urdf.xacro_expr import Evaluator, ExprRefusedError

MAX_XACRO_FILE_BYTES = 2_000_000  # one xacro or YAML file read during expansion
MAX_MACRO_CALLS = 20_000  # tiago_dual-sized robots make a few hundred
MAX_SECONDS = 15.0  # wall clock inside the expansion (the child's own limit is above)
REFUSED_HINT = "; pass --trust-xacro to expand it with xacro itself (in a sandbox)"


class _RefusalError(Exception):
    """Raised inside xacro; carries the refusal out through xacro's exception wrapping."""

    def __init__(self, message: str, needle: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.needle = needle


class _State:
    """Roots, files read and counters of one expansion."""

    def __init__(self, top: Path, roots: Sequence[Path]) -> None:
        self.top = top
        self.roots = [Path(os.path.realpath(r)) for r in roots]
        self.files: dict[str, str] = {}
        self.calls = 0
        self.start = time.monotonic()

    def confine(self, path: str, what: str) -> Path:
        real = Path(os.path.realpath(path))
        if not any(real.is_relative_to(r) for r in self.roots):
            raise _RefusalError(
                f"{what} {path!r} is outside the allowed directories", os.path.basename(path)
            )
        return real

    def read(self, path: str, what: str) -> bytes:
        real = self.confine(path, what)
        data = read_regular(real, max_bytes=MAX_XACRO_FILE_BYTES, what=what)
        if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
            raise _RefusalError(f"{what} {path!r} declares a DOCTYPE/entities", path)
        self.files[str(real)] = data.decode("utf-8", "replace")
        return data


def find_package(name: str, start: Path) -> Path | None:
    """`$(find NAME)`: an ancestor of `start` or a ROS_PACKAGE_PATH entry that is package NAME."""
    for d in (start, *start.parents):
        if d.name == name and is_package(d, name):
            return d
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if not entry:
            continue
        for d in (Path(entry), Path(entry) / name):
            if is_package(d, name):
                return d.resolve()
    return None


def _extension(state: _State, xacro: Any, text: str) -> str:
    inner = text[2:-1].split()
    cmd, args = (inner[0], inner[1:]) if inner else ("", [])
    if cmd == "arg" and len(args) == 1:
        mapping = xacro.substitution_args_context.get("arg", {})
        if args[0] not in mapping:
            raise xacro.XacroException(f"undefined substitution argument {args[0]!r}")
        return str(mapping[args[0]])
    if cmd == "dirname" and not args:
        return os.path.dirname(os.path.abspath(xacro.filestack[-1] or state.top))
    if cmd == "find" and len(args) == 1:
        found = find_package(args[0], state.top.parent.resolve())
        if found is None:
            raise _RefusalError(
                f"$(find {args[0]}): no package {args[0]!r} (a directory whose package.xml "
                "names it) among the file's ancestors or ROS_PACKAGE_PATH",
                text,
            )
        if found not in state.roots:
            state.roots.append(found)
        return str(found)
    raise _RefusalError(
        f"$({cmd} ...) is not allowed (only $(arg), $(find), $(dirname))", f"$({cmd}"
    )


def _patches(state: _State, xacro: Any) -> dict[str, Any]:
    """Replacements for xacro's module-level functions that could run code or read files."""
    import xml.dom.minidom

    real_macro_call = xacro.handle_macro_call

    def load_yaml(filename: str) -> Any:
        path = xacro.abs_filename_spec(filename)
        data = state.read(path, "YAML file").decode("utf-8", "replace")
        return xacro.YamlListWrapper.wrap(loads_yaml(data, path).data)

    def safe_eval(expr: str, symbols: Any, _locals: Any = None) -> Any:
        calls = {xacro._global_symbols["xacro"]["load_yaml"]: load_yaml}
        calls[xacro._global_symbols["load_yaml"]] = load_yaml
        try:
            return Evaluator(lambda name: symbols[name], calls)(expr)
        except ExprRefusedError as exc:
            raise _RefusalError(f"expression ${{{expr.strip()}}}: {exc}", expr.strip()) from None

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            path = os.path.join(xacro.root_dir, filename)
            return xml.dom.minidom.parseString(state.read(path, "included file"))
        return xml.dom.minidom.parseString(inp) if isinstance(inp, str | bytes) else inp

    def handle_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        state.calls += 1
        if state.calls > MAX_MACRO_CALLS:
            raise _RefusalError(f"more than {MAX_MACRO_CALLS} macro calls")
        if time.monotonic() - state.start > MAX_SECONDS:
            raise _RefusalError(f"expansion took longer than {MAX_SECONDS:g} s")
        return real_macro_call(node, macros, symbols)

    return {
        "safe_eval": safe_eval,
        "eval_extension": lambda s: _extension(state, xacro, s),
        "parse": parse,
        "handle_macro_call": handle_macro_call,
        "load_yaml": load_yaml,
    }


@contextlib.contextmanager
def _patched(state: _State) -> Iterator[Any]:
    import xacro

    patches = _patches(state, xacro)
    saved = {name: getattr(xacro, name) for name in patches}
    try:
        for name, fn in patches.items():
            setattr(xacro, name, fn)
        yield xacro
    finally:
        for name, fn in saved.items():
            setattr(xacro, name, fn)


def _unwrap(exc: BaseException) -> BaseException:
    inner = exc
    while getattr(inner, "exc", None) is not None:
        inner = inner.exc  # type: ignore[attr-defined]
    return inner


_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)


def _blank(match: re.Match[str]) -> str:
    """A comment replaced by its newlines only, so that offsets keep their line numbers."""
    return "\n" * match.group(0).count("\n")


def _line_of(state: _State, needle: str | None) -> tuple[str, int | None]:
    """The file and line where `needle` (an expression or path) first appears."""
    if needle:
        for name, text in state.files.items():
            code = _COMMENT.sub(_blank, text)
            at = code.find(needle)
            if at >= 0:
                return name, code.count("\n", 0, at) + 1
    return str(state.top), None


def expand_safe(path: Path, roots: Sequence[Path], mappings: dict[str, str] | None = None) -> bytes:
    """The expanded URDF bytes of a foreign xacro file; XacroRefusedError or InputError."""
    state = _State(path, roots)
    with _patched(state) as xacro:
        try:
            doc = xacro.process_file(str(path), mappings=mappings or {})
        except BaseException as exc:  # xacro wraps everything in XacroException
            inner = _unwrap(exc)
            if isinstance(inner, _RefusalError):
                file, line = _line_of(state, inner.needle)
                raise XacroRefusedError(
                    inner.message + REFUSED_HINT, file=file, line=line
                ) from None
            if isinstance(inner, InputError):
                raise
            text = " ".join(f"{type(inner).__name__}: {inner}".split())[:400]
            raise InputError(f"xacro expansion failed: {text}", file=path) from None
    out: bytes = doc.toprettyxml(indent="  ", encoding="utf-8")
    return out


def child_main(argv: Sequence[str]) -> int:
    """Entry point in the limited child: argv = [path, root...]; URDF on stdout."""
    import json

    path, roots = Path(argv[0]), [Path(r) for r in argv[1:]]
    try:
        sys.stdout.buffer.write(expand_safe(path, roots))
    except InputError as exc:
        kind = "refused" if isinstance(exc, XacroRefusedError) else "failed"
        report = {"kind": kind, "message": exc.message, "file": exc.file, "line": exc.line}
        sys.stderr.write("\n" + json.dumps(report) + "\n")
        return 1
    return 0
