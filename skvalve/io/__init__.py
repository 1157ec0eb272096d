"""Output helpers: ParaView time series (VTU + PVD) of solid-mechanics results via meshio."""

from .timeseries import TimeSeriesWriter, step_fields

__all__ = ["TimeSeriesWriter", "step_fields"]
