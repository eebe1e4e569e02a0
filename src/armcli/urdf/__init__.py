"""Robots as URDF: strict reader, typed view, sources (spec | URDF | xacro), tree, meshes.

May import `armcli.compiler` and below (a spec is compiled in memory to get its URDF).
"""
