"""The ``backend`` section: settings of one backend, today the Toyota HSR over ROS 1 (topics,
frames, safety timeouts)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any

from pydantic import Field, model_validator

from pfctl.mission.errors import field_error
from pfctl.mission.types import MissionModel, Positive

Topic = Annotated[str, Field(pattern=r"^/[A-Za-z0-9_/]*[A-Za-z0-9_]$")]
"""A global ROS 1 graph name (``/hsrb/base_scan``)."""
Frame = Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_/]*$")]
"""A tf frame id without a leading slash (``base_footprint``)."""


class HsrConfig(MissionModel):
    """The Toyota HSR over ROS 1 (``--backend hsr``): the topics, frames and safety timeouts.

    The defaults are the names of Toyota's ROS 1 stack; ``pfctl sim serve-hsr`` serves exactly
    these, so the same mission drives the robot and the simulated house. Person detections come
    from one of two sources (§II-E: the paper's OpenPose ran beside the robot):

    * ``person_labels`` (the default): an instance-segmentation image published by a person
      detector (e.g. an OpenPose node on another machine, or the simulator):
      ``sensor_msgs/Image``, encoding ``16UC1`` (``mono16``), the RGB image's size and stamp;
      pixel value 0 is no person, value ``v > 0`` is person ``(v - 1) // 4`` (an index that only
      has to be stable within one image) and body part ``(v - 1) % 4`` (0 unknown, 1 head,
      2 torso, 3 leg).
    * ``person_keypoints`` (when set; then ``person_labels`` is not subscribed and must be left
      out or null): 2-D keypoints and boxes as a ``sensor_msgs/PointCloud``
      (:mod:`pfctl.bags.person_keypoints`): ``header.stamp`` = the stamp of the RGB image
      the detector ran on (paired with RGB, depth and camera_info like the labels),
      ``header.frame_id`` = the RGB optical frame; one point per keypoint, ``x`` = pixel column,
      ``y`` = pixel row, ``z`` = confidence (≤ 0: not found); channels ``person`` (an index
      stable within the message) and ``part`` (OpenPose BODY_25 index 0-24; 25 = the box's
      top-left corner, 26 = its bottom-right corner, for detectors that give boxes), one value
      per point. The follower places each person in 3-D from the depth around its torso.
    """

    laser: Topic = "/hsrb/base_scan"
    """sensor_msgs/LaserScan of the base laser (REP-117 ranges)."""
    rgb: Topic = "/hsrb/head_rgbd_sensor/rgb/image_rect_color"
    """sensor_msgs/Image, rgb8 or bgr8."""
    depth: Topic = "/hsrb/head_rgbd_sensor/depth_registered/image_rect_raw"
    """sensor_msgs/Image registered to the RGB image: 16UC1 (mm) or 32FC1 (m)."""
    camera_info: Topic = "/hsrb/head_rgbd_sensor/rgb/camera_info"
    """sensor_msgs/CameraInfo of the RGB image."""
    person_labels: Topic | None = "/pfctl/person_labels"
    """sensor_msgs/Image 16UC1 person/part labels (see above); null: no camera detections
    (unless ``person_keypoints`` is set)."""
    person_keypoints: Topic | None = None
    """sensor_msgs/PointCloud of 2-D keypoints/boxes (see above), e.g. ``/pfctl/person_keypoints``
    from a relay of an OpenPose node; null: the person labels are the source."""
    joint_states: Topic = "/hsrb/joint_states"
    """sensor_msgs/JointState with head_pan_joint and head_tilt_joint."""
    odom: Topic = "/hsrb/odom"
    """nav_msgs/Odometry of the base."""
    pose: Topic | None = None
    """geometry_msgs/PoseStamped of the base in the map (e.g. ``/global_pose``); null: tf."""
    command_velocity: Topic = "/hsrb/command_velocity"
    """geometry_msgs/Twist to the omnidirectional base."""
    head_command: Topic = "/hsrb/head_trajectory_controller/command"
    """trajectory_msgs/JointTrajectory to the head."""
    move_base: Topic = "/move_base/move"
    """The move_base_msgs/MoveBaseAction server."""
    speech: Topic | None = "/pfctl/say"
    """std_msgs/String of what the robot says (it asks a person who shows it their back to look
    at it), for a text-to-speech node to speak: on an HSR a relay to Toyota's ``/talk_request``.
    The robot speaks only while some node listens; null: it never does."""
    viewpoint_stop: Topic | None = "/viewpoint_controller/stop"
    """std_srvs/Empty called (when it exists) before the head is commanded; null: never."""
    ground_truth: Topic | None = "/ground_truth"
    """Namespace of the simulator's truth (``robot``, ``people``, ``collisions``) used for the
    metrics only, never by the follower; absent on a real robot."""
    map_frame: Frame = "map"
    odom_frame: Frame = "odom"
    base_frame: Frame = "base_footprint"
    stale_timeout: Positive = 0.5
    """Zero velocity is published when the laser or the pose is older than this (wall) time, s."""
    connect_timeout: Positive = 20.0
    """How long to wait at start for the first laser scan, pose and clock, s."""

    @model_validator(mode="before")
    @classmethod
    def _one_person_source(cls, data: Any) -> Any:
        """With ``person_keypoints`` the keypoints are the person source: ``person_labels`` is
        then null (not subscribed); naming a labels topic as well is an error."""
        if not isinstance(data, Mapping) or data.get("person_keypoints") is None:
            return data
        labels = data.get("person_labels")
        if labels is not None:
            raise field_error(
                ("person_keypoints",),
                f"expected one person source, got person_labels ({labels}) as well: leave "
                "person_labels out (or null) to take the people from the keypoints",
            )
        return {**data, "person_labels": None}


class BackendConfig(MissionModel):
    """Backend-specific settings."""

    hsr: HsrConfig = HsrConfig()
