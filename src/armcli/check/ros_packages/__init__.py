"""`armcli check DIR` over ROS 2 packages: the failures between their files.

Between the URDF, its controllers, the launch files, the MoveIt config and the Gazebo
plugins, read from the files (docs/check.md).

Every file is data: launch files are parsed (Python with `ast`, XML and YAML with their
parsers), never run; reads stay inside DIR, bounded.
"""
