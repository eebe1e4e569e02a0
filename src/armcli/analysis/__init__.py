"""What a robot's model says about it, without simulating it.

Stance, ground contacts, support polygon, static balance, zero-moment point, workspace
and reach, box search; the linearised PD loop, its stability bound and one verdict per
loop, shared by `check`, `simulate` and `tune`.

May import `armcli.robot` and below.
"""
