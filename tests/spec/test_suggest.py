"""Did you mean: the closest valid key, from the model's own field names at that place."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.errors import SpecError
from armcli.spec.load import loads_spec
from armcli.spec.model import RobotSpec
from armcli.spec.suggest import did_you_mean, keys_at


def test_keys_at_walks_models_mappings_and_options() -> None:
    assert keys_at(RobotSpec, ()) == sorted(f.alias or n for n, f in RobotSpec.model_fields.items())
    link_keys = keys_at(RobotSpec, ("arm", "links", "forearm_link"))
    assert "mass" in link_keys and "origin" not in keys_at(RobotSpec, ("poses", "home"))
    assert keys_at(RobotSpec, ("arm", "links", "forearm_link")) == keys_at(
        RobotSpec, ("mobile_base", "links", "base_link")
    )
    assert keys_at(RobotSpec, ("no", "such", "place")) == []


@pytest.mark.parametrize(
    ("path", "hint"),
    [
        (("arm", "links", "hand_link", "mas"), "; did you mean 'mass'?"),
        (("control", "gain"), "; did you mean 'gains'?"),
        (("arm", "links", "hand_link", "zzzzzz"), ""),  # nothing close: no guess
        (("arm", "links", 0), ""),
    ],
)
def test_did_you_mean(path: tuple[str | int, ...], hint: str) -> None:
    assert did_you_mean(RobotSpec, path) == hint


def test_spec_error_suggests_the_key(default_spec_path: Path) -> None:
    text = default_spec_path.read_text()
    bad = text.replace("    mass: 0.3\n", "    mas: 0.3\n", 1)
    assert bad != text
    with pytest.raises(SpecError) as info:
        loads_spec(bad, "armcli.yaml")
    assert "mas: unknown key; did you mean 'mass'?" in str(info.value)
