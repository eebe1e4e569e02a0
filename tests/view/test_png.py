"""`armcli render`: image size, the robot's colours, poses that show, and the tool point."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from armcli.errors import InputError
from armcli.view.png import AMBIENT, load_urdf, render_png
from armcli.view.scene import load_robot
from tests.helpers import run_cli

SHADE_TOL = 0.05  # max distance in RGB [0..1] of a pixel from a shade of a material colour
MIN_PIXELS = 150  # a drawn part covers at least this many pixels at 1200x600
TIP_TOL = 1e-6  # [m] forward kinematics vs closed form
L = 0.3  # [m] forearm and hand length (seed)
MOUNT = (0.15, 0.32)  # [m] (x, z) of the forearm joint: mount 0.15 ahead, 0.1 + 0.2 + 0.02 up


def tip(q1: float, q2: float) -> tuple[float, float, float]:
    """Closed-form hand tip for the planar 2-link arm rotating about +y (x = L sin, z = L cos)."""
    x = MOUNT[0] + L * math.sin(q1) + L * math.sin(q1 + q2)
    z = MOUNT[1] + L * math.cos(q1) + L * math.cos(q1 + q2)
    return (x, 0.0, z)


@pytest.fixture(scope="module")
def robot(default_spec_path: Path):
    return load_robot(default_spec_path)


@pytest.fixture(scope="module")
def renders(robot, tmp_path_factory: pytest.TempPathFactory):
    """The default robot at home and folded, rendered once for the module."""
    out = tmp_path_factory.mktemp("render")
    urdf = load_urdf(robot.xml, robot.source)
    return {
        pose: render_png(urdf, robot.poses[pose], out / f"{pose}.png", tool=robot.tool)
        for pose in ("home", "folded")
    }


def pixels(path: Path) -> np.ndarray:
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=float) / 255.0


def size(path: Path) -> tuple[int, int]:
    with Image.open(path) as im:
        return im.size


def shade_mask(img: np.ndarray, rgb: tuple[float, float, float]) -> np.ndarray:
    """Pixels equal to k * rgb with k in the lit range [AMBIENT, 1] (Lambert shading)."""
    c = np.asarray(rgb)
    k = img @ c / (c @ c)
    resid = np.linalg.norm(img - k[..., None] * c, axis=-1)
    return (resid < SHADE_TOL) & (k > AMBIENT - SHADE_TOL) & (k < 1 + SHADE_TOL)


def test_image_size_and_determinism(renders, robot, tmp_path: Path) -> None:
    home = renders["home"]
    assert size(home.path) == (1200, 600) == (home.width, home.height)
    again = render_png(
        load_urdf(robot.xml), robot.poses["home"], tmp_path / "again.png", tool=robot.tool
    )
    assert again.path.read_bytes() == home.path.read_bytes()
    small = render_png(load_urdf(robot.xml), {}, tmp_path / "small.png", size=(640, 320))
    assert size(small.path) == (640, 320)


def test_robot_colours_are_present(renders, default_spec_path: Path) -> None:
    from armcli.spec.load import load_spec

    spec = load_spec(default_spec_path)
    used = {lk.material for lk in spec.all_links().values() if lk.material}
    img = pixels(renders["home"].path)
    for name in sorted(used):
        rgb = spec.materials[name].rgba[:3]
        assert shade_mask(img, rgb).sum() > MIN_PIXELS, f"{name} {rgb} not drawn"


def test_tool_point_matches_closed_form(renders) -> None:
    # The brief: hand tip at (0.15, 0, 0.92) at q = 0.
    assert renders["home"].tool_position == pytest.approx((0.15, 0.0, 0.92), abs=TIP_TOL)
    assert renders["folded"].tool_position == pytest.approx(
        tip(1.5, math.pi / 2),
        abs=TIP_TOL,  # the spec's folded pose
    )


def _yellow_box(path: Path) -> tuple[int, int]:
    """(width, height) [px] of the yellow forearm in the side view (right half)."""
    img = pixels(path)
    side = img[:, img.shape[1] // 2 :]
    ys, xs = np.nonzero(shade_mask(side, (1.0, 1.0, 0.0)))
    return int(xs.max() - xs.min()), int(ys.max() - ys.min())


def test_two_poses_give_different_images(renders) -> None:
    a, b = pixels(renders["home"].path), pixels(renders["folded"].path)
    changed = (np.abs(a - b).max(axis=-1) > 0.1).sum()
    assert changed > 10 * MIN_PIXELS
    # Side view: the forearm stands upright at home and lies along x when folded (q1 = 1.5).
    w_home, h_home = _yellow_box(renders["home"].path)
    w_fold, h_fold = _yellow_box(renders["folded"].path)
    assert h_home > 3 * w_home
    assert w_fold > 3 * h_fold


def test_out_of_limits_is_refused_and_nothing_written(robot, tmp_path: Path) -> None:
    out = tmp_path / "x.png"
    with pytest.raises(InputError, match=r"outside its limits \[0, 1.5708\]"):
        render_png(load_urdf(robot.xml), {"forearm_hand_joint": 2.0}, out, field="--q")
    with pytest.raises(InputError, match="unknown movable joint 'elbow'"):
        render_png(load_urdf(robot.xml), {"elbow": 0.0}, out, field="--q")
    assert not out.exists()


def test_cli_render_q_and_errors(root: Path, tmp_path: Path) -> None:
    out = tmp_path / "r.png"
    ok = run_cli(["render", "--q", "pi/4,pi/4", "-o", str(out)], root)
    assert ok.returncode == 0, ok.stderr
    x, _, z = tip(math.pi / 4, math.pi / 4)
    assert ok.stdout.strip() == (
        f"wrote {out} (1200x600 px) at --q pi/4,pi/4; tool at ({x:.3f}, 0.000, {z:.3f}) m"
    )
    default = run_cli(["render", "-o", str(tmp_path / "d.png")], root)
    # no --pose or --q: the message says which configuration was drawn (the spec's home is 0)
    assert "at q = 0, the pose 'home', as no --pose or --q was given" in default.stdout
    assert "(others: --pose home|" in default.stdout
    (tmp_path / "d.png").unlink()
    both = run_cli(["render", "--pose", "home", "--q", "0,0", "-o", str(tmp_path / "b.png")], root)
    assert both.returncode == 2
    assert both.stderr.strip() == "error: --pose: give --pose or --q, not both"
    count = run_cli(["render", "--q", "0.1", "-o", str(tmp_path / "c.png")], root)
    assert count.returncode == 2
    assert "expected 2 value(s), one for each of arm_base_forearm_joint, forearm_hand_joint" in (
        count.stderr
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.png"]


def test_cli_render_takes_a_limit_as_printed_and_says_it_replaced(
    root: Path, tmp_path: Path
) -> None:
    """1.5708 is the course's stop pi/2 as printed (3.7e-6 above it): the stop, with a note;
    rendering over an existing PNG says `replaced`."""
    out = tmp_path / "r.png"
    out.write_bytes(b"old")
    res = run_cli(["render", "--q", "1.5708,0", "-o", str(out)], root)
    assert res.returncode == 0, res.stderr
    assert "note: arm_base_forearm_joint = 1.5708 is taken as its upper limit" in res.stderr
    x, _, z = tip(math.pi / 2, 0.0)
    assert res.stdout.strip() == (
        f"replaced {out} (1200x600 px) at --q 1.5708,0; tool at ({x:.3f}, 0.000, {z:.3f}) m"
    )


def test_mesh_geometry_is_drawn_and_a_missing_mesh_is_an_error(tmp_path: Path) -> None:
    import trimesh

    trimesh.creation.icosphere(radius=0.2).export(tmp_path / "ball.stl")
    link = (
        '<link name="a"><visual><geometry><mesh filename="{}"/></geometry>'
        '<material name="red"><color rgba="1 0 0 1"/></material></visual></link>'
    )
    ok = f'<robot name="r">{link.format("ball.stl")}</robot>'
    res = render_png(load_urdf(ok, "m.urdf", tmp_path), {}, tmp_path / "m.png")
    assert shade_mask(pixels(res.path), (1.0, 0.0, 0.0)).sum() > 10 * MIN_PIXELS
    bad = f'<robot name="r">{link.format("package://nope/cube.stl")}</robot>'
    with pytest.raises(InputError, match=r"mesh file not found: package://nope/cube\.stl"):
        load_urdf(bad, "bad.urdf", tmp_path)


def test_foreign_textured_meshes(root: Path, tmp_path: Path) -> None:
    """A URDF nobody here wrote, with COLLADA meshes whose colour comes from a texture
    material (trimesh TextureVisuals, which has no face_colors): it used to crash."""
    import sysconfig

    share = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share"
    urdf = share / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
    if not urdf.is_file():
        pytest.skip("example-robot-data (dev dependency) not installed")
    out = tmp_path / "ur5.png"
    # Its package.xml names example_robot_descriptions, so package://example-robot-data/
    # is only a root when given (a folder's name alone is not a package, issue 15).
    pkg = f"example-robot-data={share / 'example-robot-data'}"
    args = ("--q", "0,-1.2,1.5,0,0,0", "--package-dir", pkg, "-o", str(out))
    proc = run_cli(["render", str(urdf), *args], root)
    assert proc.returncode == 0, proc.stderr
    img = pixels(out)
    assert img.shape[:2] == (600, 1200)
    # The UR5's dark grey links cover a good part of the 3-D view (left half).
    dark = (img[:, :600].max(axis=-1) < 0.35).sum()
    assert dark > MIN_PIXELS


def test_render_resolves_package_meshes_with_package_dir(tmp_path: Path) -> None:
    """`render` uses check's mesh resolver: package://NAME needs --package-dir NAME=PATH;
    without it the mesh is missing, which render warns about and draws the rest."""
    import trimesh

    pkg = tmp_path / "meshes_pkg"
    pkg.mkdir()
    trimesh.creation.box(extents=(0.1, 0.1, 0.3)).export(pkg / "hand.stl")
    urdf = tmp_path / "robot" / "arm.urdf"
    urdf.parent.mkdir()
    urdf.write_text(
        '<robot name="meshy"><link name="base"/><link name="hand"><visual><geometry>'
        '<mesh filename="package://my_meshes/hand.stl"/></geometry></visual></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="hand"/>'
        '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        "</robot>"
    )
    out = tmp_path / "meshy.png"
    # Without it the mesh is missing: render draws the rest and warns (issue 19: it exited 2)
    res = run_cli(["render", str(urdf), "-o", str(out)], tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stderr == (
        f"warning: {urdf}: mesh 'package://my_meshes/hand.stl' not found, not drawn "
        "(--package-dir NAME=PATH points package://NAME at a folder)\n"
    )
    assert out.is_file()
    out.unlink()
    res = run_cli(
        ["render", str(urdf), "-o", str(out), "--package-dir", f"my_meshes={pkg}"], tmp_path
    )
    assert res.returncode == 0, res.stderr
    with Image.open(out) as img:
        assert img.size == (1200, 600)


@pytest.mark.parametrize(
    "name", ["mesh_file_uri.urdf", "mesh_relative_escape.urdf", "mesh_absolute.urdf"]
)
def test_render_leaves_out_meshes_outside_the_allowed_directories(
    name: str, tmp_path: Path, root: Path
) -> None:
    """Such a mesh is never read: render draws the rest and says why it is missing (issue 19:
    a URDF written with its author's absolute paths, kortex's gen3_2f85.urdf, exited 2)."""
    out = tmp_path / "robot.png"
    res = run_cli(
        ["render", str(root / "tests" / "bad_inputs" / "urdf" / name), "-o", str(out)], root
    )
    assert res.returncode == 0, res.stderr
    assert "outside the allowed directories" in res.stderr and ", not drawn" in res.stderr
    assert res.stderr.startswith("warning: ") and out.is_file()


def test_render_never_opens_a_mesh_outside_the_roots(tmp_path: Path) -> None:
    # A FIFO blocks whoever opens it: the render finishing proves it was never opened.
    outside = tmp_path / "outside"
    outside.mkdir()
    os.mkfifo(outside / "trap.stl")
    urdf = tmp_path / "robot" / "arm.urdf"
    urdf.parent.mkdir()
    urdf.write_text(
        f'<robot name="r"><link name="a"><visual><geometry><mesh filename="file://{outside}'
        '/trap.stl"/></geometry></visual><visual><geometry><box size="0.1 0.1 0.1"/>'
        "</geometry></visual></link></robot>"
    )
    res = run_cli(["render", str(urdf), "-o", str(tmp_path / "r.png")], tmp_path)
    assert res.returncode == 0, res.stderr
    assert f"mesh 'file://{outside}/trap.stl' resolves to" in res.stderr


def _many_joints(n: int) -> str:
    parts = ['<robot name="many"><link name="l0"/>']
    for i in range(1, n + 1):
        parts.append(
            f'<joint name="a_rather_long_joint_name_{i}" type="revolute"><parent link="l{i - 1}"/>'
            f'<child link="l{i}"/><origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<link name="l{i}"><visual><geometry><box size="0.02 0.02 0.05"/></geometry>'
            "</visual></link>"
        )
    return "".join(parts) + "</robot>"


@pytest.mark.parametrize("joints", [2, 29, 45])  # the course arm, G1, PR2
def test_the_title_never_overprints_the_views(joints: int) -> None:
    """PR2 and G1: a title wrapped over many lines ran into the views' own titles."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from armcli.view.png import render_figure

    urdf = load_urdf(_many_joints(joints), "many.urdf")
    fig = render_figure(urdf, {j: 0.0 for j in urdf.actuated_joint_names}, name="many")
    renderer = FigureCanvasAgg(fig).get_renderer()
    title = fig._suptitle.get_window_extent(renderer)
    assert title.y1 <= fig.bbox.y1  # inside the picture
    for ax in fig.axes:  # below the title: the views' titles and their axes
        assert ax.title.get_window_extent(renderer).y1 < title.y0
        assert ax.get_window_extent(renderer).y1 < title.y0
    if joints > 29:  # too many to list: the title says how many it left out
        assert "more joint(s)" in fig._suptitle.get_text()
