"""`armcli ros-package`: ROS 2 description, bringup and MoveIt config packages from a spec.

May import `armcli.urdf` and below.
"""
