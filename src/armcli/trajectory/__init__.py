"""Joint trajectories: the JointTrajectory-shaped files, plan's own layout, the reference.

The formats a user or `plan` writes (message.py, jointtext.py, the course's brace form in
brace.py) and the piecewise-polynomial reference the simulator and plan's certification
track (reference.py). Below export and sim: what a trajectory is does not depend on who runs it.
"""
