"""The simulated HSR's body in PyBullet, for the eye: a base, a mast and a head that pans and tilts.

The bodies are visual only (no collision shape): the base's collisions are decided in 2-D by the
simulator, and neither the laser's rays nor the robot's own motion may hit them. The camera does
see them, as a real robot's camera sees its own base when it looks down.
"""

from __future__ import annotations

import pybullet as p

from pfctl.core.robot import HeadState, Pose2D

#: Height of the base cylinder, metres.
BASE_HEIGHT = 0.35
#: Half extents of the head box (depth, width, height), metres; the camera is ahead of it.
HEAD_HALF = (0.05, 0.11, 0.06)
BODY_RGBA = (0.92, 0.92, 0.92, 1.0)
DARK_RGBA = (0.15, 0.15, 0.17, 1.0)


class RobotBody:
    """Base (radius ``radius``), mast up to the head pivot, and the head box."""

    def __init__(self, client: int, radius: float, pivot_height: float) -> None:
        self.client = client
        self.pivot_height = pivot_height
        mast_h = max(pivot_height - HEAD_HALF[2] - BASE_HEIGHT, 0.05)
        self.base = p.createMultiBody(
            baseMass=0.0,
            baseVisualShapeIndex=p.createVisualShape(
                p.GEOM_CYLINDER,
                radius=radius,
                length=BASE_HEIGHT,
                rgbaColor=BODY_RGBA,
                physicsClientId=client,
            ),
            basePosition=(0.0, 0.0, BASE_HEIGHT / 2),
            physicsClientId=client,
        )
        self.mast = p.createMultiBody(
            baseMass=0.0,
            baseVisualShapeIndex=p.createVisualShape(
                p.GEOM_BOX,
                halfExtents=(0.06, 0.08, mast_h / 2),
                rgbaColor=BODY_RGBA,
                physicsClientId=client,
            ),
            basePosition=(0.0, 0.0, BASE_HEIGHT + mast_h / 2),
            physicsClientId=client,
        )
        self._mast_z = BASE_HEIGHT + mast_h / 2
        self.head = p.createMultiBody(
            baseMass=0.0,
            baseVisualShapeIndex=p.createVisualShape(
                p.GEOM_BOX, halfExtents=HEAD_HALF, rgbaColor=DARK_RGBA, physicsClientId=client
            ),
            basePosition=(0.0, 0.0, pivot_height),
            physicsClientId=client,
        )

    @property
    def body_ids(self) -> tuple[int, int, int]:
        return (self.base, self.mast, self.head)

    def sync(self, pose: Pose2D, head: HeadState) -> None:
        """Place the bodies at the base pose with the head at its pan/tilt angles."""
        yaw = p.getQuaternionFromEuler((0.0, 0.0, pose.theta))
        p.resetBasePositionAndOrientation(
            self.base, (pose.x, pose.y, BASE_HEIGHT / 2), yaw, physicsClientId=self.client
        )
        p.resetBasePositionAndOrientation(
            self.mast, (pose.x, pose.y, self._mast_z), yaw, physicsClientId=self.client
        )
        # pitch about y is positive looking down in PyBullet's Euler angles; HSR tilt is the
        # opposite (negative looking down)
        head = p.getQuaternionFromEuler((0.0, -head.tilt, pose.theta + head.pan))
        p.resetBasePositionAndOrientation(
            self.head, (pose.x, pose.y, self.pivot_height), head, physicsClientId=self.client
        )


__all__ = ["RobotBody"]
