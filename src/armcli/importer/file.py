"""`armcli import FILE`: read a URDF or xacro file, import it, write the spec atomically."""

from __future__ import annotations

from pathlib import Path

from armcli.errors import ExistingFileError, InputError
from armcli.importer.run import GainSource, ImportResult, import_urdf
from armcli.io.files import write_file_atomic
from armcli.urdf.source import XACRO_SUFFIX, Trust, read_urdf_file
from armcli.urdf.xacro_sandbox import expand_untrusted


def parse_args(values: list[str]) -> dict[str, str]:
    """`NAME:=VALUE` xacro arguments -> {NAME: VALUE}; InputError on a malformed one."""
    out = {}
    for v in values:
        name, sep, value = v.partition(":=")
        if not sep or not name:
            raise InputError(f"expected NAME:=VALUE, got {v!r}", field="ARGS")
        out[name] = value
    return out


def read_source(path: Path, args: dict[str, str], trust_xacro: Trust) -> tuple[bytes, str]:
    """The URDF bytes of `path` (a xacro file expanded) and how to name it in the spec."""
    label = path.as_posix()
    if args:
        label += " (" + " ".join(f"{k}:={v}" for k, v in args.items()) + ")"
        if not trust_xacro:
            raise InputError(
                "xacro arguments are passed to xacro itself: add --trust-xacro (sandboxed)",
                field="ARGS",
            )
        if path.suffix != XACRO_SUFFIX and b"xacro" not in path.read_bytes()[:100_000]:
            raise InputError("NAME:=VALUE arguments are for xacro files", field="ARGS")
        xml = expand_untrusted(path, mappings=args, unsandboxed=trust_xacro == "unsandboxed")
        return xml, label
    return read_urdf_file(path, trust_xacro=trust_xacro).text, label


def import_file(
    path: Path,
    out: Path,
    *,
    args: dict[str, str] | None = None,
    trust_xacro: Trust = False,
    arm_root: str | None = None,
    force: bool = False,
    gains: GainSource | None = None,
) -> ImportResult:
    """Import `path` and write the spec to `out` (all or nothing; never over a file unless forced).

    Raises:
        ExistingFileError: `out` exists and `force` is not set (nothing was read or written).
        InputError: the file is unusable or holds what a spec cannot.
    """
    if out.exists() and not force:
        raise ExistingFileError(f"{out} exists; pass --force to replace it", file=out)
    if out.is_dir():
        raise InputError("is a directory; give the spec file to write", file=out, field="--out")
    xml, label = read_source(path, args or {}, trust_xacro)
    result = import_urdf(xml, label, out, arm_root=arm_root, source_dir=path.parent, gains=gains)
    write_file_atomic(out, result.text)
    return result
