"""`armcli import`: any URDF (or safely expanded xacro) -> a spec that builds it back.

May import `armcli.urdf` and below (a sibling of check, sim, ros, view, export).
"""
