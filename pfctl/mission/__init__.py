"""The mission YAML boundary (DESIGN.md): the only place that knows the mission file format.

Everything below it receives plain typed objects: the sections are small frozen models whose
fields are SI values, and :meth:`Mission.layout` turns the ``map`` section into the
:class:`pfctl.core.mapping.house.HouseLayout` value types.

=====================  ======================================================================
:mod:`.sections`       the mission file (:class:`Mission`) and its sections
:mod:`.map`            the ``map`` section and the checks of the house's geometry
:mod:`.scenario`       the ``scenario`` section (the simulator's people)
:mod:`.backend`        the ``backend`` section (the HSR's topics and frames)
:mod:`.tree`           behavior-tree node models (``behavior.tree``), the paper's tree
:mod:`.types`          value types of fields (finite numbers, polygons, limits), the base model
:mod:`.params`         keys the core declares (``FromCore``), and core parameters built from them
:mod:`.loading`        :func:`load_mission`: ``extends``, ``include``, merging, validation
:mod:`.errors`         every failure as one line ``<file>:<line>: <key.path>: <expected>``
:mod:`.schema`         the JSON Schema (``pfctl mission schema``)
:mod:`.edit`           round-trip editing of a mission file (``pfctl map annotate``)
=====================  ======================================================================
"""

from pfctl.mission.backend import BackendConfig, HsrConfig
from pfctl.mission.loading import load_mission, loads_mission, merge_mission_data
from pfctl.mission.map import DoorSpec, MapConfig, ObstacleSpec, RegionSpec, SensorModel
from pfctl.mission.scenario import Clothes, Person, ScenarioConfig, ScenarioRandomization
from pfctl.mission.schema import dump_json_schema
from pfctl.mission.sections import (
    BehaviorConfig,
    BeliefConfig,
    CameraConfig,
    ControlConfig,
    LaserConfig,
    Mission,
    PerceptionConfig,
    Pose,
    PoseNoise,
    PredictionConfig,
    RobotConfig,
    SearchConfig,
    SensorsConfig,
    SvrParams,
    TrackingConfig,
    Weighting,
)
from pfctl.mission.tree import Composite, Decorator, Parallel, Repeat, Retry, Timeout, TreeNode

__all__ = [
    "BackendConfig",
    "BehaviorConfig",
    "BeliefConfig",
    "CameraConfig",
    "Clothes",
    "Composite",
    "ControlConfig",
    "Decorator",
    "DoorSpec",
    "HsrConfig",
    "LaserConfig",
    "MapConfig",
    "Mission",
    "ObstacleSpec",
    "Parallel",
    "PerceptionConfig",
    "Person",
    "Pose",
    "PoseNoise",
    "PredictionConfig",
    "RegionSpec",
    "Repeat",
    "Retry",
    "RobotConfig",
    "ScenarioConfig",
    "ScenarioRandomization",
    "SearchConfig",
    "SensorModel",
    "SensorsConfig",
    "SvrParams",
    "Timeout",
    "TrackingConfig",
    "TreeNode",
    "Weighting",
    "dump_json_schema",
    "load_mission",
    "loads_mission",
    "merge_mission_data",
]
