"""What a robot's model says about it: stance, ground contacts, support polygon, workspace.

May import `armcli.robot` and below.
"""
