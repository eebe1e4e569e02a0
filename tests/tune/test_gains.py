"""The gain vector layout: stacking and reading back per joint are inverses."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.tune import gains

JOINTS = ("shoulder", "elbow", "wrist")
KP = (50.0, 20.0, 5.0)
KD = (5.0, 2.0, 0.5)


def test_stack_then_split_gives_back_kp_and_kd() -> None:
    g = gains.stack(KP, KD)
    kp, kd = gains.split(g)
    assert kp.tolist() == list(KP) and kd.tolist() == list(KD)


def test_each_entry_has_the_name_of_its_joint_and_gain() -> None:
    g = gains.stack(KP, KD)
    named = dict(zip(gains.param_names(JOINTS), g.tolist(), strict=True))
    per_joint = gains.by_joint(g, JOINTS)
    for j, name in enumerate(JOINTS):
        assert per_joint[name] == (named[f"kp:{name}"], named[f"kd:{name}"]) == (KP[j], KD[j])
        assert gains.of_joint(g, j) == (KP[j], KD[j])


def test_kp_and_kd_of_different_lengths_are_refused() -> None:
    with pytest.raises(ValueError, match="equal-length"):
        gains.stack(np.ones(2), np.ones(3))
