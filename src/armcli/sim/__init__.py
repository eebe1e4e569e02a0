"""`armcli simulate`: the arm under PD control along a trajectory, with stability checks.

May import `armcli.urdf` and below.
"""
