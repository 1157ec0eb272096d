"""Input and output: the Abaqus input reader (:mod:`.abaqus`) and ParaView time series (VTU + PVD) of
solid-mechanics results via meshio (:mod:`.timeseries`)."""

from .abaqus import AbaqusModel, AbaqusParseError, read_model
from .timeseries import TimeSeriesWriter, step_fields

__all__ = ["AbaqusModel", "AbaqusParseError", "read_model", "TimeSeriesWriter", "step_fields"]
