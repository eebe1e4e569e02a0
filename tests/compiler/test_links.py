"""General-form links and passthrough XML through the real xacro: what goes in comes out."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from armcli.compiler.expand import build, expand_urdfs
from armcli.compiler.meshfiles import MeshNames, package_path
from armcli.spec.load import load_spec, loads_spec

SPEC = """
name: general
materials: {grey: {rgba: [0.5, 0.5, 0.5, 1], gazebo: Gazebo/Grey}}
arm:
  links:
    base_link:
      visual:
        - name: shell
          geometry: {mesh: {filename: meshes/base.dae, scale: [0.001, 0.001, 0.001]}}
          origin: {xyz: [0, 0, 0.1], rpy: [0, 0, pi/2]}
          material: grey
        - geometry: {mesh: {filename: "package://other_pkg/meshes/cap.stl"}}
          material: {name: "Grey Steel", rgba: [0.4, 0.4, 0.45, 1]}
      collision:
        - geometry: {box: {size: [0.2, 0.2, 0.1]}}
          origin: {xyz: [0, 0, 0.05]}
        - geometry: {sphere: {radius: 0.05}}
      inertial: {shape: collision, density: 500}
  joints: {}
passthrough:
  - '<gazebo reference="base_link"><selfCollide>true</selfCollide>
     <note>${not_xacro} $(nor_this)</note></gazebo>'
"""


def _urdf(text: str, tmp: Path | None = None) -> etree._Element:
    if tmp is None:
        spec = loads_spec(text)
        return etree.fromstring(expand_urdfs(spec)["standalone_arm.urdf"])
    (tmp / "robot.yaml").write_text(text)
    build(tmp / "robot.yaml", tmp / "out")
    return etree.parse(str(tmp / "out" / "standalone_arm.urdf")).getroot()


def test_shapes_come_out_in_order_with_their_materials() -> None:
    root = _urdf(SPEC)
    link = root.find("link[@name='base_link']")
    assert link is not None
    visuals = link.findall("visual")
    assert [v.get("name") for v in visuals] == ["shell", None]
    mesh = visuals[0].find("geometry/mesh")
    assert mesh is not None and mesh.get("scale") == "0.001 0.001 0.001"
    assert visuals[0].find("origin").get("rpy") == "0 0 1.5707963267948966"
    assert visuals[0].find("material").attrib == {"name": "grey"}
    inline = visuals[1].find("material")
    assert inline is not None and inline.get("name") == "Grey Steel"
    assert inline.find("color").get("rgba") == "0.4 0.4 0.45 1"
    assert [c.find("geometry")[0].tag for c in link.findall("collision")] == ["box", "sphere"]  # type: ignore[index]
    # density 500 kg/m³ x the 0.2 x 0.2 x 0.1 box, by the box macro about its centre
    inertial = link.find("inertial")
    assert inertial is not None
    mass = float(inertial.find("mass").get("value"))  # type: ignore[arg-type]
    assert abs(mass - 2.0) < 1e-12
    assert inertial.find("origin").get("xyz") == "0 0 0.05"


def test_passthrough_is_copied_literally() -> None:
    root = _urdf(SPEC)
    note = root.find("gazebo/note")
    assert note is not None and note.text == "${not_xacro} $(nor_this)"  # not evaluated by xacro
    assert root.find("gazebo/selfCollide").text == "true"


def test_mesh_paths_stay_where_they_are(tmp_path: Path) -> None:
    in_memory = _urdf(SPEC.replace("joints: {}", "joints: {}"), None)
    uri = in_memory.find("link/visual/geometry/mesh").get("filename")
    assert uri is not None and Path(uri).is_absolute() and uri.endswith("meshes/base.dae")
    built = _urdf(SPEC, tmp_path)
    uris = [m.get("filename") for m in built.iter("mesh")]
    assert uris == ["../meshes/base.dae", "package://other_pkg/meshes/cap.stl"]


def test_mesh_names_for_packages_and_outputs(tmp_path: Path) -> None:
    names = MeshNames(tmp_path / "spec", tmp_path / "spec" / "urdf")
    assert names.uri("meshes/a.stl") == "../meshes/a.stl"
    assert names.uri("/abs/b.stl") == "/abs/b.stl"
    assert names.uri("package://p/c.stl") == "package://p/c.stl"
    ros = MeshNames(tmp_path, package="robot_description")
    assert ros.uri("meshes/a.stl") == "package://robot_description/meshes/a.stl"
    assert ros.uri("parts/visual/a.stl") == "package://robot_description/meshes/visual/a.stl"
    assert package_path("a.stl") == "meshes/a.stl"


def test_spec_file_directory_is_the_base(tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    spec_path = tmp_path / "sub" / "robot.yaml"
    spec_path.write_text(SPEC)
    assert load_spec(spec_path).base_dir == tmp_path / "sub"
