"""`scene.xml` beside the model, in the style of mujoco_menagerie: include, floor, light, sky.

The model file stays free of world dressing so that it can be included into
other scenes; this file is what a user opens in `python -m mujoco.viewer`.

The floor has friction 0 (FLOOR_FRICTION): MuJoCo gives a contact the larger friction of
its two geoms, Gazebo's ODE the smaller (and Gazebo's ground plane has mu 100), so only a
frictionless floor lets each robot geom's own coefficient count, as in Gazebo: a caster
of mu 0.1 on MuJoCo's default floor of 1 would grip like a wheel. The drive
(`simulate --cmd-vel`, drive.model) stands on the same floor, so the exported scene
drives as it does.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.xmlfmt import to_bytes

SCENE = "scene.xml"
FLOOR_FRICTION = (0.0, 0.0, 0.0)  # sliding, torsional, rolling: see the module docstring


def scene_xml(model_file: str, model_name: str, header: str | None = None) -> bytes:
    """The scene file: includes `model_file` (relative) and adds floor, light and sky."""
    root = etree.Element("mujoco", model=f"{model_name} scene")
    etree.SubElement(root, "include", file=model_file)
    visual = etree.SubElement(root, "visual")
    etree.SubElement(
        visual, "headlight", diffuse="0.6 0.6 0.6", ambient="0.3 0.3 0.3", specular="0 0 0"
    )
    etree.SubElement(visual, "rgba", haze="0.15 0.25 0.35 1")
    etree.SubElement(visual, "global", azimuth="120", elevation="-20")
    asset = etree.SubElement(root, "asset")
    etree.SubElement(
        asset,
        "texture",
        type="skybox",
        builtin="gradient",
        rgb1="0.3 0.5 0.7",
        rgb2="0 0 0",
        width="512",
        height="3072",
    )
    etree.SubElement(
        asset,
        "texture",
        type="2d",
        name="groundplane",
        builtin="checker",
        mark="edge",
        rgb1="0.2 0.3 0.4",
        rgb2="0.1 0.2 0.3",
        markrgb="0.8 0.8 0.8",
        width="300",
        height="300",
    )
    etree.SubElement(
        asset,
        "material",
        name="groundplane",
        texture="groundplane",
        texuniform="true",
        texrepeat="5 5",
        reflectance="0.2",
    )
    world = etree.SubElement(root, "worldbody")
    etree.SubElement(world, "light", pos="0 0 1.5", dir="0 0 -1", directional="true")
    etree.SubElement(
        world,
        "geom",
        name="floor",
        size="0 0 0.05",
        type="plane",
        material="groundplane",
        friction=" ".join(f"{f:g}" for f in FLOOR_FRICTION),
    )
    return to_bytes(root, header_comment=header)
