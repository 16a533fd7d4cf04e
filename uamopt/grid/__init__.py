"""The airspace grid of Sec. 3 (:mod:`~uamopt.grid.grid`) and the geometry of straight segments
through its cells (:mod:`~uamopt.grid.geometry`). Nothing here knows about cities or risk."""

from uamopt.grid.grid import AirspaceGrid, altitude_band, build_grid, check_memory, memory_limit_bytes

__all__ = ["AirspaceGrid", "altitude_band", "build_grid", "check_memory", "memory_limit_bytes"]
