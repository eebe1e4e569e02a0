"""Exports of the robot to other simulators' formats (MuJoCo MJCF)."""
