"""Foreign xacro, safe by default: xacro's own machinery with the code execution taken out.

xacro's macros, properties, blocks, includes, conditionals and arguments are
kept (they are xacro's own functions, unchanged); what is replaced is every
place where the file could run code or reach the machine:

- `${...}` is evaluated by xacro.expr's AST whitelist instead of `eval`;
- `$(...)`: `arg`, `dirname`, `find PKG` (armcli.io.packages: --package-dir,
  AMENT_PREFIX_PATH, ROS_PACKAGE_PATH, the enclosing package), `env` / `optenv`
  from the user's `--env VAR=VALUE` only (xacro.args); `eval`, `cwd` and `anon`
  are refused;
- includes and `load_yaml` read only regular files inside the allowed roots
  (the file's directory and package, the packages `find` resolved, with their real
  directories: packages.real_roots), size-capped, with DOCTYPE/entities refused;
  YAML goes through xacro.yaml_tags (xacro's unit tags, duplicate keys warned);
- macro calls and wall time are bounded (exponential macro bombs).

A refusal is an XacroRefusedError naming the construct, file and line; any other
failure is an InputError with the same (nothing is re-raised without its cause).
The expansion runs in xacro.sandbox's resource-limited child process, so memory
is bounded too (`child_main` is that child's entry point).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import sys
import time
from collections.abc import Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, NoReturn

import yaml

from armcli.errors import InputError, XacroRefusedError
from armcli.io.packages import PackageLookup
from armcli.xacro.args import Expansion, XacroInputs
from armcli.xacro.expr import Evaluator, ExprRefusedError
from armcli.xacro.lines import annotate, collect, expand_call, source_map
from armcli.xacro.state import ExpansionState, ProblemError
from armcli.xacro.yaml_tags import YamlRefusedError
from armcli.xacro.yaml_tags import load_yaml as read_yaml

MAX_MACRO_CALLS = 20_000  # tiago_dual-sized robots make a few hundred
MAX_SECONDS = 15.0  # wall clock inside the expansion (the child's own limit is above)
REFUSED_HINT = "; pass --trust-xacro to expand it with xacro itself (in a sandbox)"


def find_package(name: str, start: Path, packages: PackageLookup | None = None) -> Path | None:
    """`$(find NAME)`: armcli.io.packages' lookup from the file being read."""
    return (packages or PackageLookup()).find(name, start)


def _current(xacro: Any, state: ExpansionState) -> Path:
    return Path(xacro.filestack[-1] if xacro.filestack and xacro.filestack[-1] else state.top)


def _find(state: ExpansionState, xacro: Any, name: str, text: str) -> str:
    found = state.inputs.packages.find(name, _current(xacro, state))
    if found is None:
        raise ProblemError(
            f"$(find {name}): no package {name!r} (looked in --package-dir, "
            "AMENT_PREFIX_PATH, ROS_PACKAGE_PATH and the packages enclosing the file); "
            f"pass --package-dir {name}=PATH or source the workspace that has it",
            text,
            refused=False,
        )
    state.add_package(found)
    return str(found)


def _env(state: ExpansionState, args: list[str], text: str, optional: bool) -> str:
    name = args[0]
    if name in state.inputs.env:
        return state.inputs.env[name]
    if optional:
        state.optenv_defaults.append(name)
        return " ".join(args[1:])
    raise ProblemError(
        f"$(env {name}): armcli does not read its own environment; pass --env {name}=VALUE",
        text,
        refused=False,
    )


def _declared_later(state: ExpansionState, xacro: Any, name: str) -> str:
    """Why a default the file declares does not apply: its <xacro:arg> comes after the use.

    UR's ur.urdf.xacro reads `name` in its <robot> tag, a line above `default="ur"`;
    xacro takes arguments in document order, so real xacro refuses it the same way.
    """
    code = _COMMENT.sub(_blank, state.files.get(os.path.realpath(_current(xacro, state)), ""))
    quoted = "[\"']" + re.escape(name) + "[\"']"
    found = re.search(r"<xacro:arg\s+name=" + quoted + r"\s+default=([\"'])(.*?)\1", code)
    if found is None:
        return ""
    line = code.count("\n", 0, found.start()) + 1
    return (
        f" (its default {found.group(2)!r}, line {line}, is declared after this use; "
        "xacro applies a default only from its declaration on)"
    )


def _extension(state: ExpansionState, xacro: Any, text: str) -> str:
    inner = text[2:-1].split()
    cmd, args = (inner[0], inner[1:]) if inner else ("", [])
    if cmd == "arg" and len(args) == 1:
        if args[0] not in state.args:
            raise ProblemError(
                f"undefined xacro argument {args[0]!r}: pass {args[0]}:=VALUE after the file"
                + _declared_later(state, xacro, args[0]),
                text,
                refused=False,
            )
        return str(state.args[args[0]])
    if cmd == "dirname" and not args:
        return os.path.dirname(os.path.abspath(_current(xacro, state)))
    if cmd == "find" and len(args) == 1:
        return _find(state, xacro, args[0], text)
    if cmd in ("env", "optenv") and (len(args) == 1 or (cmd == "optenv" and args)):
        return _env(state, args, text, optional=cmd == "optenv")
    if cmd in ("eval", "cwd", "anon"):
        raise ProblemError(
            f"$({cmd} ...) is not allowed (it runs Python or reads the machine)", f"$({cmd}"
        )
    raise ProblemError(f"{text}: unknown or malformed substitution", text, refused=False)


def _messages(state: ExpansionState, xacro: Any) -> dict[Any, Any]:
    """The functions xacro exposes to expressions -> safe versions (keyed by the original)."""
    ns = xacro._global_symbols["xacro"]

    def said(kind: str) -> Any:
        def record(*args: Any, **_: Any) -> str:
            where = _current(xacro, state)
            state.warnings.append(f"{where}: xacro.{kind}: {' '.join(map(str, args))}")
            return ""

        return record

    def fatal(*args: Any) -> None:
        raise ProblemError(f"xacro.fatal: {' '.join(map(str, args))}", "fatal", refused=False)

    out = {ns[k]: said(k) for k in ("message", "warning", "error") if k in ns}
    out[ns["fatal"]] = fatal
    out[ns["arg"]] = lambda name: state.args[name]
    out[ns["print_location"]] = lambda *a, **k: ""
    for name in ("tokenize", "abs_filename", "dotify"):
        out[ns[name]] = ns[name]  # pure functions of their arguments
    python = xacro._global_symbols["python"]
    for name in ("sorted", "range"):  # deprecated top-level aliases of python.*
        if name in xacro._global_symbols:
            out[xacro._global_symbols[name]] = python[name]
    return out


def _patches(state: ExpansionState, xacro: Any) -> dict[str, Any]:
    """Replacements for xacro's module-level functions that could run code or read files."""
    import xml.dom.minidom

    real_macro_call = xacro.handle_macro_call
    units = {u.value.tag: u.value.conversion_constant for u in xacro.ConstructUnits}
    calls: dict[Any, Any] = _messages(state, xacro)

    def evaluate(expr: str, symbols: Any) -> Any:
        try:
            return Evaluator(lambda name: symbols[name], calls)(expr)
        except ExprRefusedError as exc:
            raise ProblemError(f"expression ${{{expr.strip()}}}: {exc}", expr.strip()) from None
        except Exception as exc:
            inner = _unwrap(exc)
            if isinstance(inner, ProblemError):  # from a property evaluated lazily inside
                raise inner from None
            # NameError, TypeError, ...: the file's own mistake
            text = f"expression ${{{expr.strip()}}}: {type(inner).__name__}: {inner}"
            raise ProblemError(text, expr.strip(), refused=False) from None

    def load_yaml(filename: str) -> Any:
        path = xacro.abs_filename_spec(filename)
        data = state.read(path, "YAML file")
        xacro.filestack.append(path)
        try:
            doc = read_yaml(
                data,
                path,
                units,
                lambda text: evaluate(text, xacro._global_symbols),
                state.warnings.append,
            )
        except YamlRefusedError as exc:
            raise ProblemError(exc.message, file=path, line=exc.line) from None
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            why = getattr(exc, "problem", None) or str(exc).splitlines()[0]
            line = mark.line + 1 if mark is not None else None
            raise ProblemError(
                f"malformed YAML: {why}", refused=False, file=path, line=line
            ) from None
        finally:
            xacro.filestack.pop()
        return xacro.YamlListWrapper.wrap(doc)

    calls[xacro._global_symbols["xacro"]["load_yaml"]] = load_yaml
    calls[xacro._global_symbols["load_yaml"]] = load_yaml

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            path = os.path.join(xacro.root_dir, filename)
            state.confine(path, "included file")
            if not os.path.isfile(path):  # as xacro: an IOError, so optional="true" works
                xacro.filestack.pop()
                err = FileNotFoundError(2, "No such file or directory", path)
                raise xacro.XacroException(f"No such file or directory: {path}", exc=err)
            text = state.read(path, "included file")
            doc = xml.dom.minidom.parseString(text)  # str: UTF-8
            annotate(doc, text, len(state.sources))  # each element's file and line
            state.sources.append(os.path.abspath(path))
            return doc
        return xml.dom.minidom.parseString(inp) if isinstance(inp, str | bytes) else inp

    def get_include_files(filename_spec: str, symbols: Any) -> Iterator[str]:
        spec = xacro.abs_filename_spec(xacro.eval_text(filename_spec, symbols))
        for filename in state.include_files(spec):
            xacro.all_includes.append(filename)
            yield filename

    def handle_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        state.calls += 1
        if state.calls > MAX_MACRO_CALLS:
            raise ProblemError(f"more than {MAX_MACRO_CALLS} macro calls")
        if time.monotonic() - state.start > MAX_SECONDS:
            raise ProblemError(f"expansion took longer than {MAX_SECONDS:g} s")
        return expand_call(node, lambda: real_macro_call(node, macros, symbols))

    def warning(*args: Any, **_: Any) -> None:
        state.warnings.append(f"{_current(xacro, state)}: xacro: {' '.join(map(str, args))}")

    return {
        "safe_eval": evaluate,
        "eval_extension": lambda s: _extension(state, xacro, s),
        "parse": parse,
        "get_include_files": get_include_files,
        "handle_macro_call": handle_macro_call,
        "load_yaml": load_yaml,
        "warning": warning,
    }


@contextlib.contextmanager
def _patched(state: ExpansionState) -> Iterator[Any]:
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


def _line_of(
    state: ExpansionState, needle: str | None, first: Sequence[str] = ()
) -> tuple[str, int | None]:
    """The file and line where `needle` (an expression or path) first appears.

    The files in `first` (the macro's and the file being read when it failed) are
    searched before the others.
    """
    if needle:
        names = [*(os.path.realpath(f) for f in first), *state.files]
        for name in dict.fromkeys(names):
            code = _COMMENT.sub(_blank, state.files.get(name, ""))
            at = code.find(needle)
            if at >= 0:
                return name, code.count("\n", 0, at) + 1
    return str(state.top), None


def _context(xacro: Any) -> list[str]:
    """Where xacro was when it failed: the macro's defining file, then the file being read."""
    files = []
    for macro in reversed(xacro.macrostack or []):
        if macro.history and macro.history[-1]:
            files.append(macro.history[-1][-1])
    files += [f for f in reversed(xacro.filestack or []) if f]
    return files


def _raise(state: ExpansionState, xacro: Any, exc: Exception, path: Path) -> NoReturn:
    """The InputError (XacroRefusedError for a refusal) a failed expansion stands for."""
    inner = _unwrap(exc)
    where = _context(xacro)
    if isinstance(inner, ProblemError):
        if inner.file is not None:
            file, line = inner.file, inner.line
        else:
            file, line = _line_of(state, inner.needle, where)
        if inner.refused:
            raise XacroRefusedError(inner.message + REFUSED_HINT, file=file, line=line) from None
        raise InputError(inner.message, file=file, line=line) from None
    if isinstance(inner, InputError):
        raise inner from None  # read_regular's own message names its file
    text = " ".join(f"{type(inner).__name__}: {inner}".split())[:400]
    raise InputError(f"xacro expansion failed: {text}", file=where[0] if where else path) from None


def expand_safe(
    path: Path,
    roots: Sequence[Path],
    mappings: dict[str, str] | None = None,
    inputs: XacroInputs | None = None,
) -> bytes:
    """The expanded URDF bytes of a foreign xacro file; XacroRefusedError or InputError."""
    return expand_safe_report(path, roots, inputs or XacroInputs(args=mappings or {}))[0]


def expand_safe_report(
    path: Path, roots: Sequence[Path], inputs: XacroInputs
) -> tuple[bytes, Expansion]:
    """The expanded URDF bytes and what the expansion used (arguments, warnings)."""
    state = ExpansionState(path, roots, inputs)
    with _patched(state) as xacro:
        try:
            doc = xacro.process_file(str(path), mappings=state.args)
        except Exception as exc:  # xacro wraps everything in XacroException
            _raise(state, xacro, exc, path)
    tags = collect(doc)  # the positions out of the document: the bytes are xacro's
    out: bytes = doc.toprettyxml(indent="  ", encoding="utf-8")
    return out, replace(state.expansion(), source_map=source_map(out, tags, state.sources))


def child_main(argv: Sequence[str]) -> int:
    """Entry point in the limited child: argv = [path, request JSON]; URDF on stdout.

    The request: {"roots": [...], "args": {...}, "env": {...}, "packages": lookup JSON}.
    The last stderr line is a JSON report: the Expansion, or the refusal/failure.
    """
    path, request = Path(argv[0]), json.loads(argv[1])
    inputs = XacroInputs(
        args=dict(request.get("args", {})),
        env=dict(request.get("env", {})),
        packages=PackageLookup.from_json(request["packages"])
        if "packages" in request
        else PackageLookup(),
    )
    try:
        out, used = expand_safe_report(path, [Path(r) for r in request["roots"]], inputs)
    except InputError as exc:
        kind = "refused" if isinstance(exc, XacroRefusedError) else "failed"
        report = {"kind": kind, "message": exc.message, "file": exc.file, "line": exc.line}
        sys.stderr.write("\n" + json.dumps(report) + "\n")
        return 1
    sys.stdout.buffer.write(out)
    sys.stderr.write("\n" + json.dumps({"kind": "ok", "expansion": used.to_dict()}) + "\n")
    return 0


def request_json(roots: Sequence[Path], inputs: XacroInputs) -> str:
    """The child's request for `roots` and `inputs` (the environment read now)."""
    return json.dumps(
        {
            "roots": [str(r) for r in roots],
            "args": dict(inputs.args),
            "env": dict(inputs.env),
            "packages": inputs.packages.to_json(),
        }
    )
