"""Make an ament install prefix from a directory of ROS package sources, as colcon would.

`python bench/ament_workspace.py SRC PREFIX` leaves in PREFIX what
`colcon build --symlink-install --merge-install` leaves for description packages:

- `PREFIX/share/<name>/...`: real directories, one symlink per source file (ament_cmake's
  symlink install links files, not directories), `<name>` from the package's package.xml
  (not its directory name);
- `PREFIX/share/ament_index/resource_index/packages/<name>`: the empty marker file by which
  `ament_index_python.get_package_share_directory` (and so `xacro`'s `$(find)`) finds it;
- `PREFIX/setup.sh`: `. PREFIX/setup.sh` sets AMENT_PREFIX_PATH as a sourced workspace does.

Packages are found as colcon and rospack find them: a directory with a package.xml is a
package and is not searched further; COLCON_IGNORE / AMENT_IGNORE / CATKIN_IGNORE and
hidden directories are skipped. Nothing is built: armcli needs only the shared files.
The prefix is rebuilt from scratch (an existing PREFIX must hold a previous one).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import sys
from pathlib import Path

IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
CMAKE_KEYWORDS = ("USE_SOURCE_PERMISSIONS", "OPTIONAL", "MESSAGE_NEVER", "FILES_MATCHING")
INDEX = Path("share/ament_index/resource_index/packages")
_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")


def package_name(directory: Path) -> str | None:
    """The <name> of `directory`/package.xml (None when there is none)."""
    xml = directory / "package.xml"
    if not xml.is_file():
        return None
    found = _NAME.search(xml.read_text(encoding="utf-8", errors="replace"))
    return found.group(1) if found else None


def find_packages(src: Path) -> dict[str, Path]:
    """Package name -> source directory, crawling `src` as colcon does."""
    out: dict[str, Path] = {}
    for root, dirs, _files in os.walk(src):
        here = Path(root)
        if any((here / m).exists() for m in IGNORE_MARKERS):
            dirs[:] = []
            continue
        name = package_name(here)
        if name is not None:
            if name in out:
                sys.exit(f"duplicate package {name!r}: {out[name]} and {here}")
            out[name] = here
            dirs[:] = []  # a package's subdirectories are its own
            continue
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
    return out


def install_rules(src: Path, name: str) -> list[tuple[Path, Path]]:
    """(source file or directory, destination under share/) pairs from CMakeLists.txt.

    Reads `install(DIRECTORY ...)` and `install(FILES ...)` rules whose DESTINATION is under
    `share/` (`${PROJECT_NAME}` and `${CATKIN_PACKAGE_SHARE_DESTINATION}` substituted; rules
    with other variables are skipped). `dir/` installs the directory's contents, `dir` the
    directory itself, as in CMake. Without a CMakeLists.txt (ament_python), the whole tree.
    """
    cmake = src / "CMakeLists.txt"
    if not cmake.is_file():
        return [(src, Path("share") / name)]
    text = re.sub(r"#[^\n]*", "", cmake.read_text(encoding="utf-8", errors="replace"))
    text = text.replace("${PROJECT_NAME}", name)
    text = text.replace("${CATKIN_PACKAGE_SHARE_DESTINATION}", f"share/{name}")
    rules: list[tuple[Path, Path]] = [(src / "package.xml", Path("share") / name)]
    for body in re.findall(r"\binstall\s*\(([^)]*)\)", text, flags=re.IGNORECASE):
        words = body.split()
        if not words or words[0] not in ("DIRECTORY", "FILES") or "DESTINATION" not in words:
            continue
        at = words.index("DESTINATION")
        dest = words[at + 1].strip('"').rstrip("/")
        items = [w.strip('"') for w in words[1:at] if w not in CMAKE_KEYWORDS]
        if not dest.startswith("share/") or "${" in dest:
            continue
        for item in items:
            if "${" in item:
                continue
            path = src / item.rstrip("/")
            if words[0] == "DIRECTORY" and item.endswith("/"):
                rules += [(child, Path(dest)) for child in sorted(path.glob("*"))]
            else:
                rules.append((path, Path(dest)))
    return rules


def install_package(name: str, src: Path, prefix: Path) -> int:
    """Link `src`'s installed files into `prefix` one symlink per file; the file count."""
    count = 0
    for source, dest in install_rules(src, name):
        if source.is_file():
            target = prefix / dest / source.name
            target.parent.mkdir(parents=True, exist_ok=True)
            if not target.exists():
                target.symlink_to(source)
                count += 1
            continue
        if not source.is_dir():
            continue
        base = dest if source == src else dest / source.name
        for root, dirs, files in os.walk(source):
            here = Path(root)
            dirs[:] = sorted(
                d for d in dirs if not d.startswith(".") and package_name(here / d) is None
            )
            target = prefix / base / here.relative_to(source)
            target.mkdir(parents=True, exist_ok=True)
            for f in sorted(f for f in files if not f.startswith(".")):
                if not (target / f).exists():
                    (target / f).symlink_to(here / f)
                    count += 1
    marker = prefix / INDEX / name
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_bytes(b"")
    return count


def make_prefix(src: Path, prefix: Path) -> dict[str, Path]:
    """Build the install prefix; the packages it holds."""
    src, prefix = src.resolve(), prefix.absolute()
    if prefix.exists():
        if not (prefix / INDEX).is_dir():
            sys.exit(f"{prefix} exists and is not an install prefix; not touching it")
        shutil.rmtree(prefix)
    packages = find_packages(src)
    files = sum(install_package(n, d, prefix) for n, d in sorted(packages.items()))
    (prefix / "setup.sh").write_text(
        "# source me: AMENT_PREFIX_PATH as a sourced ROS 2 workspace sets it\n"
        f'export AMENT_PREFIX_PATH="{prefix}${{AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}}"\n',
        encoding="utf-8",
    )
    print(f"{prefix}: {len(packages)} packages, {files} file symlinks")
    return packages


def main(argv: list[str] | None = None) -> int:
    """Command line: SRC PREFIX."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("src", type=Path, help="directory holding package sources (e.g. corpus/src)")
    ap.add_argument("prefix", type=Path, help="install prefix to (re)create")
    args = ap.parse_args(argv)
    make_prefix(args.src, args.prefix)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
