"""Which OpenGL backend MuJoCo's offscreen renderer can use here: EGL, OSMesa or none.

A camera sensor's image is rendered offscreen, headless: EGL (a GPU's, or Mesa's
llvmpipe on the CPU: Debian `libegl1 libegl-mesa0 libgl1-mesa-dri`) or OSMesa (Debian
`libosmesa6`). MUJOCO_GL=egl or osmesa picks one; MUJOCO_GL=disable none; otherwise
EGL is tried first. The answer comes from creating a context, as the camera does, so
`armcli --version` cannot say yes where a camera would fail. PyOpenGL binds one platform
per process: once EGL has been tried, OSMesa is tried only if OpenGL was not loaded.
"""

from __future__ import annotations

import os
import sys
from typing import Any

BACKENDS = {"egl": "EGL", "osmesa": "OSMesa"}
DISABLED = ("disable", "disabled", "off", "false", "0")
INSTALL_HINT = "install Debian libegl1 libegl-mesa0 libgl1-mesa-dri (EGL) or libosmesa6 (OSMesa)"
_state: dict[str, Any] = {}


def _context_class(key: str) -> Any:
    if key == "egl":
        from mujoco.egl import GLContext
    else:
        from mujoco.osmesa import GLContext
    return GLContext


def _try(key: str) -> tuple[Any, str]:
    """(GLContext class, "") if a context can be made with backend `key`, else (None, why)."""
    before = os.environ.get("PYOPENGL_PLATFORM")
    try:
        cls = _context_class(key)
        ctx = cls(8, 8)
        ctx.make_current()
        ctx.free()
        return cls, ""
    except Exception as exc:  # ImportError, OSError, EGL and OSMesa errors: no backend
        if before is None and "OpenGL" not in sys.modules:
            os.environ.pop("PYOPENGL_PLATFORM", None)
        return None, f"{BACKENDS[key]}: {type(exc).__name__}: {str(exc).splitlines()[0][:120]}"


def _probe() -> tuple[str | None, Any, str]:
    wanted = os.environ.get("MUJOCO_GL", "").lower().strip()
    if wanted in DISABLED:
        return None, None, f"MUJOCO_GL={wanted}"
    order = [wanted] if wanted in BACKENDS else list(BACKENDS)
    why = []
    for key in order:
        if key == "osmesa" and os.environ.get("PYOPENGL_PLATFORM", "osmesa") != "osmesa":
            why.append("OSMesa: PyOpenGL is bound to another platform in this process")
            continue
        cls, reason = _try(key)
        if cls is not None:
            return BACKENDS[key], cls, ""
        why.append(reason)
    return None, None, "; ".join(why)


def backend() -> str | None:
    """The backend's name (EGL, OSMesa) if MuJoCo can render offscreen here (probed once)."""
    if "name" not in _state:
        _state["name"], _state["cls"], _state["why"] = _probe()
    name: str | None = _state["name"]
    return name


def why_none() -> str:
    """Why `backend()` is None."""
    backend()
    why: str = _state["why"]
    return why


def context(width: int, height: int) -> Any:
    """A current GL context of the backend (call only when `backend()` is not None)."""
    backend()
    ctx = _state["cls"](width, height)
    ctx.make_current()
    return ctx


def describe() -> str:
    """One line for `armcli --version`: the backend, or why cameras render nothing."""
    name = backend()
    if name is not None:
        return f"{name} (MuJoCo offscreen rendering of camera sensors)"
    return f"none ({why_none()}; camera sensors publish no image: {INSTALL_HINT})"
