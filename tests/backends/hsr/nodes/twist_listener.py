"""Records ``/hsrb/command_velocity`` for the tests (a ROS 1 node): one line ``CMD t vx vy wz``
per Twist received, ``t`` = ``time.monotonic()`` at receipt (one clock for all processes on
Linux); ``READY`` once subscribed."""

from __future__ import annotations

import sys
import time

from pfctl.backends.hsr.ros_import import import_ros_module, import_rospy


def main() -> None:
    rospy = import_rospy()
    twist = import_ros_module("geometry_msgs.msg").Twist
    rospy.init_node("twist_listener", argv=[sys.argv[0]], disable_signals=True)

    def on_twist(m: object) -> None:
        print("CMD", time.monotonic(), m.linear.x, m.linear.y, m.angular.z, flush=True)

    rospy.Subscriber("/hsrb/command_velocity", twist, on_twist, tcp_nodelay=True)
    print("READY", flush=True)
    while not rospy.is_shutdown():
        time.sleep(0.1)


if __name__ == "__main__":
    main()
