"""The spec's sensors simulated in MuJoCo: lidar, depth camera, camera and IMU.

One description per sensor (spec.sensors) is compiled into Gazebo's tags (compiler.sensors)
and simulated here: `rays` (the rays a lidar or a depth camera casts, the pinhole model),
`raycast` (casting them: mj_multiRay, or the compiled pinhole caster), `model` (the sites
and MuJoCo sensors added to the drive's model), `rig` (sampling every sensor at its rate
during a run), `messages` (the readings as sensor_msgs, serialised by `cdr`), `gl` and
`camera` (offscreen rendering where an OpenGL backend exists), `plot` (a scan seen from
above).
"""
