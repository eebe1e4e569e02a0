"""The camera sensor: MuJoCo's offscreen image against the pinhole the CameraInfo states.

A red box in front of a grey background: the pixels the box covers in the image are
those inside the projection, through K, of the box's face (closed form), but for a
one-pixel rim where the rasteriser and the projection may round differently. Without an
OpenGL backend the test skips, saying why (`armcli --version` says the same); with
MUJOCO_GL=disable the backend is none.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.sim.sensors import gl
from armcli.sim.sensors.rays import Pinhole
from tests.sim.sensors.rigs import boxes_and_cylinders, sensor, stage

pytest.importorskip("mujoco")

RIM_PX = 1  # the rasteriser's rounding at the box's outline


def test_without_a_backend_one_line_says_why(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MUJOCO_GL", "disable")
    monkeypatch.setattr(gl, "_state", {})
    assert gl.backend() is None
    assert gl.describe().startswith("none (MUJOCO_GL=disable; camera sensors publish no image")


def test_the_image_is_the_pinhole_of_camera_info(tmp_path: Path) -> None:
    if gl.backend() is None:
        pytest.skip(f"no OpenGL backend for MuJoCo ({gl.why_none()}); make sysdeps installs EGL")
    from armcli.sim.sensors.camera import CameraSampler

    cam = {"width": 80, "height": 60, "horizontal_fov": 1.0, "near": 0.05, "far": 20.0}
    s = sensor(type="camera", origin={"xyz": [0.0, 0.0, 0.5]}, camera=cam)
    # a box 2 m ahead of the camera, its near face (x = 1.9) 0.6 wide and 0.4 high, centred
    # 0.1 m left of and 0.05 m above the optical axis
    world = boxes_and_cylinders([(2.0, 0.1, 0.55, 0.2, 0.6, 0.4)], [])
    model, data = stage(tmp_path, world, {"cam": s})
    model.geom_rgba[model.geom("scene/box0/0").id] = (1.0, 0.0, 0.0, 1.0)
    sampler = CameraSampler("cam", s, model, np.array([0]))
    sampler.sample(0, model, data)
    image = sampler.reading(0.001, np.zeros((1, 0))).data["image"][0].astype(int)
    # lit red: far more red than green or blue (the grey floor and the black sky are not)
    red = (
        (image[..., 0] > 40)
        & (image[..., 0] > 2 * image[..., 1])
        & (image[..., 0] > 2 * image[..., 2])
    )
    assert s.camera is not None
    pin = Pinhole.of(s.camera)
    # the face's corners in the optical frame (x right = -y, y down = -z, z = x), through K
    u = pin.cx + pin.fx * np.array([-0.4, 0.2]) / 1.9  # y from 0.4 (left) to -0.2 (right)
    v = pin.cy + pin.fy * np.array([-0.25, 0.15]) / 1.9  # z from 0.25 above to 0.15 below
    vv, uu = np.mgrid[0 : pin.height, 0 : pin.width]
    inside = (uu >= u[0] + RIM_PX) & (uu <= u[1] - RIM_PX)
    inside &= (vv >= v[0] + RIM_PX) & (vv <= v[1] - RIM_PX)
    outside = (uu < u[0] - RIM_PX) | (uu > u[1] + RIM_PX)
    outside |= (vv < v[0] - RIM_PX) | (vv > v[1] + RIM_PX)
    assert inside.sum() > 100
    assert red[inside].all()
    assert not red[outside].any()
