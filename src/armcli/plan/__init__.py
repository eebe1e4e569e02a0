"""Motion planning without ROS: collision-free paths (OMPL), timing (TOPP-RA), certification.

The API is `plan.api` (planning_context, plan_motion, solve_goal); the robot comes from
`plan.robot.load_plan_robot`, the obstacles from `io.scene.load_scene`.
"""
