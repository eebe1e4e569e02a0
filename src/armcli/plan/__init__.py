"""Motion planning without ROS: collision-free paths (RRT-Connect), timing (TOPP-RA), certification.

The collision loop, RRT-Connect, the certification sweep and TOPP-RA are compiled
(`plan.native`, C++ in `_native/`); without the extension OMPL and toppra's Python package
plan, with the same collision verdicts.

The API is `plan.api` (planning_context, plan_motion, solve_goal); the robot comes from
`plan.robot.load_plan_robot`, the obstacles from `io.scene.load_scene`.
"""
