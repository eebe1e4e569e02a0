"""The whole robot driven on its wheels in MuJoCo: what `simulate --cmd-vel` runs.

The exported MuJoCo model on a floor (model.py), gazebo_ros_diff_drive's controller and
odometry (diffdrive.py) and wheel motor (wheelmotor.py), the /cmd_vel file (cmdvel.py), the
run (job.py), its results, MCAP and plot (output.py, bag.py, plot.py), and the drive as one
library call (api.py). Above sim (it drives sim's arm job) and below plan (plan --base
--execute follows its path on this drive).
"""
