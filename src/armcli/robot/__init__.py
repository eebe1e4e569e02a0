"""The one robot handle (`model.Robot`), frames, collision pairs, sampler and body maths.

May import `armcli.urdf` and below; Pinocchio is imported inside functions.
"""
