"""`armcli check`: physical-sanity rules on one URDF, their findings and reports.

May import `armcli.sim` and below: the PD verdicts are `armcli.analysis.verdict`'s and the
trajectory's zero-moment-point verdict is `armcli.sim.tipping`'s, the ones `simulate` uses.
"""
