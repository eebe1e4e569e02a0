"""One robot handle (`model.Robot`), its loading, the joint-space sampler and the body maths.

May import `armcli.urdf` and below; Pinocchio is imported inside functions.
"""
