"""`armcli check`: physical-sanity rules on one URDF, their findings and reports.

May import `armcli.urdf` and below, and `armcli.sim.stability` / `armcli.sim.verdict` (one PD bound,
one verdict per loop, for both) and `armcli.sim.tipping` (one zero-moment-point verdict).
"""
