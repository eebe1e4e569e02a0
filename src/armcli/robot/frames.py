"""Pinocchio frames by name, where a link and a joint may share one (the one lookup).

URDF names links and joints separately: ANYmal C has a link and a joint both called
`LF_HFE`. Pinocchio keeps both as frames (BODY and JOINT), so a lookup by name alone
(`getFrameId(name)`, `existFrame(name)`) raises "Several frames match the filter", and
so does `buildReducedModel`, which looks frames up by name inside. Every lookup goes
through here: a name means the link first (`link_frame`), else the one frame of that name
(`frame_id`); `reduced_model` hides the clashes from Pinocchio while it reduces.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from armcli.errors import InputError

_TAG = "#joint@armcli"  # a joint's temporary name while Pinocchio reduces the model


def link_frame(model: Any, name: str) -> int | None:
    """The Pinocchio frame id of the link `name`, None if there is no such link."""
    import pinocchio as pin

    if not model.existFrame(name, pin.BODY):
        return None
    return int(model.getFrameId(name, pin.BODY))


def frame_id(model: Any, name: str, field: str | None = None) -> int:
    """The frame `name` names: the link's, else the only frame of that name (a joint's).

    InputError naming `field` when no frame has that name.
    """
    found = link_frame(model, name)
    if found is not None:
        return found
    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    if not ids:
        raise InputError(f"no link or frame named {name!r}", field=field)
    return ids[0]  # not a link: the joint's frame first, as Pinocchio orders them


def reduced_model(model: Any, lock: Sequence[int], q: Any) -> Any:
    """`pin.buildReducedModel(model, lock, q)` for a model whose links and joints share names.

    The clashing joints (and their frames) are renamed on a copy for the reduction and
    named back in the result, so the reduced model keeps the user's names.
    """
    import pinocchio as pin

    links = {f.name for f in model.frames if f.type == pin.BODY}
    clash = {str(n) for n in list(model.names)[1:] if n in links}
    if not clash:
        return pin.buildReducedModel(model, list(lock), q)
    work = pin.Model(model)
    for j in range(1, work.njoints):
        if work.names[j] in clash:
            work.names[j] = work.names[j] + _TAG
    for i, f in enumerate(work.frames):
        if f.name in clash and f.type != pin.BODY:
            work.frames[i].name = f.name + _TAG
    out = pin.buildReducedModel(work, list(lock), q)
    for j in range(1, out.njoints):
        if out.names[j].endswith(_TAG):
            out.names[j] = out.names[j][: -len(_TAG)]
    for i, f in enumerate(out.frames):
        if f.name.endswith(_TAG):
            out.frames[i].name = f.name[: -len(_TAG)]
    return out
