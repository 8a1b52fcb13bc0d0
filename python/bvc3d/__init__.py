"""bvc3d: boundary vector cells and place cells in simulated 3-D worlds.

The compiled core does the work; this package re-exports it with numpy in and numpy out.
Stages follow the data flow: World -> agent (random_walk, flying_walk, read_trajectory) -> Sensor scan ->
BoundaryVectorLayer -> PlaceCellNetwork -> recorded samples -> bvc3d.analysis -> bvc3d.report.
"""
from ._core import (BoundaryVectorLayer, InputError, PlaceCellNetwork, Sensor, World, __version__, choose_elevations,
                    flying_walk, metric_table, model_presets, model_sensor, random_walk, read_trajectory, run_trial)
from . import analysis

__all__ = ["BoundaryVectorLayer", "InputError", "PlaceCellNetwork", "Sensor", "World", "analysis", "choose_elevations",
           "flying_walk",
           "metric_table", "model_presets", "model_sensor", "random_walk", "read_trajectory", "run_trial"]
