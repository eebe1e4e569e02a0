"""The one joint-type table: the spec's type names, the URDF reader's and the DoF agree."""

from __future__ import annotations

from typing import get_args

from armcli.spec.joint_types import (
    AXIS_TYPES,
    JOINT_DOF,
    JOINT_TYPES,
    LIMITED_TYPES,
    ONE_DOF_TYPES,
    ROTARY_TYPES,
    JointType,
)
from armcli.spec.joints import Joint, Limit


def test_the_spec_literal_and_the_table_name_the_same_types() -> None:
    assert set(get_args(JointType)) == set(JOINT_TYPES) == set(JOINT_DOF)


def test_the_derived_sets_are_subsets_of_the_table() -> None:
    assert set(LIMITED_TYPES) | set(ROTARY_TYPES) == set(ONE_DOF_TYPES)
    assert set(AXIS_TYPES) == {t for t, n in JOINT_DOF.items() if n > 0} - {"floating"}


def test_a_spec_continuous_joint_has_no_bounds_even_with_written_limits() -> None:
    lim = Limit(lower=-1.0, upper=1.0, effort=5.0, velocity=2.0)
    args = {"parent": "a", "child": "b", "axis": (0.0, 0.0, 1.0), "limit": lim}
    assert Joint(type="revolute", **args).bounds == (-1.0, 1.0)
    assert Joint(type="continuous", **args).bounds is None  # URDF ignores its lower/upper
