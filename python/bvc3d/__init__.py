"""bvc3d: boundary vector cells and place cells in simulated 3-D worlds.

The compiled core does the work; this package re-exports it with numpy in and numpy out.
Stages follow the data flow: World -> agent (random_walk, flying_walk, read_trajectory) -> Sensor scan ->
BoundaryVectorLayer -> PlaceCellNetwork -> recorded samples -> bvc3d.analysis -> bvc3d.report.
Real LiDAR recordings: Recording.open(scans, poses) -> recording.returns / recording.replay ->
localize (docs/recordings.md). Place recognition, the field's protocol against Scan Context:
place_recognition (docs/place-recognition.md). Buildings: World.from_sdf (Gazebo worlds), lidar_models, route, tour
(docs/buildings.md).
"""
from ._core import (BoundaryVectorLayer, InputError, PlaceCellNetwork, Recording, Sensor, World, __version__,
                    choose_elevations, flying_walk, localize, metric_table, model_presets, model_sensor, random_walk,
                    read_trajectory, replay_simulated, run_trial)
from ._core import place_recognition, scan_context, scan_context_distance
from ._core import lidar_models, route, tour, write_trajectory
from ._core import GridCells, HeadDirectionCells
from . import analysis
from . import worlds  # World.from_dict, World.from_triangles

__all__ = ["BoundaryVectorLayer", "InputError", "PlaceCellNetwork", "Recording", "Sensor", "World", "analysis",
           "choose_elevations", "flying_walk", "localize", "metric_table", "model_presets", "model_sensor",
           "random_walk", "read_trajectory", "replay_simulated", "run_trial"]
__all__ += ["place_recognition", "scan_context", "scan_context_distance"]
__all__ += ["lidar_models", "route", "tour", "write_trajectory"]
from ._core import HdAdjacency, combine_scales, navigate, reward_readout, shortest_path
__all__ += ["HdAdjacency", "combine_scales", "navigate", "reward_readout", "shortest_path"]
from . import authors  # the authors' controller piece by piece
__all__ += ["authors"]
__all__ += ["GridCells", "HeadDirectionCells"]
from ._core import GrowingPlaceCells
__all__ += ["GrowingPlaceCells"]
