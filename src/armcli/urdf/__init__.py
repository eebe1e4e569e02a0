"""Robots as URDF: strict reader, typed view, sources, Pinocchio loading, inertia, tree.

May import `armcli.compiler` and below (a spec is compiled in memory to get its URDF).
"""
