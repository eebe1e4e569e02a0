"""`armcli simulate`: the arm under PD control along a trajectory, with stability checks.

May import `armcli.export` and below; the stability checks are `armcli.analysis.verdict`'s,
the zero-moment point `armcli.analysis.zmp`'s.
"""
