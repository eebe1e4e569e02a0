"""armcli: typed robot-arm specs compiled to ROS-ready xacro/URDF, checked and simulated."""

__version__ = "0.1.0"
