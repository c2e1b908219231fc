"""The HSR backend over ROS 1.

Only this package may import ``rospy`` and ROS message modules, and only through
:func:`pfctl.backends.hsr.ros_import.import_rospy` (which finds Debian's ROS 1 for the venv).
Importing ``pfctl.backends.hsr`` itself imports no ROS module: ``pfctl`` without ``--backend hsr``
never loads rospy.
"""
