"""Looking at a robot: the browser viewer (sliders, poses, replay) and headless PNGs.

May import `armcli.urdf` and below.
"""
