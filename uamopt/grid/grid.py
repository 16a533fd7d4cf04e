"""The airspace grid of Sec. 3.

Local metric frame: x east, y north, z altitude above the ground datum, metres. Cell (i, j, k) is
0-based; its centre is ((i + ½)Δx, (j + ½)Δy, (k + ½)Δz), which is the paper's
x = (i − ½)Δx with its 1-based i (docs/readings.md). The grid holds a = ⌊x_max/Δx⌋ × b × c whole cells.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import GridError

if TYPE_CHECKING:
    from uamopt.scenario import Scenario


@dataclass(frozen=True)
class AirspaceGrid:
    """A regular grid of ``shape`` = (nx, ny, nz) cells of size ``cell`` = (Δx, Δy, Δz) metres.

    Examples
    --------
    >>> g = AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(50, 90, 12))
    >>> g.centre_of((1, 2, 3))
    (75.0, 125.0, 105.0)
    >>> g.index_of((75.0, 125.0, 105.0))
    (1, 2, 3)
    """

    cell: tuple[float, float, float]
    shape: tuple[int, int, int]

    def __post_init__(self) -> None:
        if any(c <= 0 for c in self.cell):
            raise GridError(f"cell size must be positive, got {self.cell}", "grid.cell", "use e.g. [50, 50, 30]")
        if any(n <= 0 for n in self.shape):
            raise GridError(
                f"the domain holds no cells (shape {self.shape})",
                "grid.extent / grid.cell",
                "make each extent at least one cell size",
            )

    @classmethod
    def from_extent(cls, cell: tuple[float, float, float], extent: tuple[float, float, float]) -> AirspaceGrid:
        """The largest grid of whole cells inside [0, x_max] × [0, y_max] × [0, z_max]."""
        shape = tuple(int(np.floor(e / c + 1e-9)) for e, c in zip(extent, cell, strict=False))
        return cls(cell=tuple(float(c) for c in cell), shape=shape)  # type: ignore[arg-type]

    # --- geometry -------------------------------------------------------------------------
    @property
    def n_cells(self) -> int:
        return int(np.prod(self.shape))

    @property
    def extent(self) -> tuple[float, float, float]:
        """(x_max, y_max, z_max) actually covered by whole cells, m."""
        return tuple(n * c for n, c in zip(self.shape, self.cell, strict=False))  # type: ignore[return-value]

    def centres(self, axis: int) -> np.ndarray:
        """Cell-centre coordinates along one axis (0 = x, 1 = y, 2 = z), m."""
        return (np.arange(self.shape[axis]) + 0.5) * self.cell[axis]

    def edges(self, axis: int) -> np.ndarray:
        """Cell-face coordinates along one axis, ``shape[axis] + 1`` values, m."""
        return np.arange(self.shape[axis] + 1) * self.cell[axis]

    @property
    def x(self) -> np.ndarray:
        return self.centres(0)

    @property
    def y(self) -> np.ndarray:
        return self.centres(1)

    @property
    def z(self) -> np.ndarray:
        return self.centres(2)

    def centre_of(self, index: tuple[int, int, int]) -> tuple[float, float, float]:
        """Centre of cell (i, j, k), m."""
        return tuple(float((i + 0.5) * c) for i, c in zip(index, self.cell, strict=False))  # type: ignore[return-value]

    def indices_of(self, points: np.ndarray) -> np.ndarray:
        """Cell indices (…, 3) of points (…, 3) in metres; points on a face go to the upper cell.

        Raises
        ------
        GridError
            If any point lies outside the grid.
        """
        pts = np.asarray(points, dtype=float)
        idx = np.floor(pts / np.asarray(self.cell)).astype(np.int64)
        # a point exactly on the far boundary belongs to the last cell
        idx = np.where(pts == np.asarray(self.extent), idx - 1, idx)
        bad = np.any((idx < 0) | (idx >= np.asarray(self.shape)), axis=-1)
        if np.any(bad):
            first = pts.reshape(-1, 3)[np.flatnonzero(bad.reshape(-1))[0]]
            raise GridError(
                f"point {tuple(float(v) for v in first)} is outside the grid",
                f"extent {self.extent}",
                "choose a point inside the domain",
            )
        return idx

    def index_of(self, point: tuple[float, float, float]) -> tuple[int, int, int]:
        """Cell index (i, j, k) of one point in metres."""
        return tuple(int(v) for v in self.indices_of(np.asarray(point, dtype=float)))  # type: ignore[return-value]

    def direction_layers(self, cruise_altitude_m: float, conflict_radius: int) -> tuple[int, int]:
        """Cell layers of a route's two directions (Sec. 4.1.2, docs/readings.md): the layer holding
        the cruise altitude, and r + 1 layers above it, the first outside its conflict zone
        (r = ``schedule.conflict_radius``), so opposite directions never conflict.

        >>> AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(50, 90, 12)).direction_layers(120.0, 1)
        (4, 6)
        """
        k = int(np.floor(cruise_altitude_m / self.cell[2] + 1e-9))
        return k, k + int(conflict_radius) + 1

    def layers_in_band(self, low_m: float, high_m: float) -> np.ndarray:
        """Layer indices k whose centre altitude satisfies low ≤ z_k ≤ high (Eq. 14)."""
        z = self.z
        return np.flatnonzero((z >= low_m - 1e-9) & (z <= high_m + 1e-9))


def altitude_band(scenario: Scenario) -> tuple[float, float]:
    """max(h_min, h'_min) ≤ h ≤ min(h_max, h'_max) (Eq. 14), m. Default [90, 300]."""
    low = max(scenario.aircraft.h_min, scenario.grid.h_min_airspace)
    high = min(scenario.aircraft.h_max, scenario.grid.h_max_airspace)
    return low, high


#: Peak memory of a run, bytes = fixed + per cell × cells, for what the run keeps of the field:
#: ``"risk"``, the risk field with its continuous arrays (``uamopt risk``, ``ua.compute_risk``);
#: ``"plan"``, Eq. 9's cells only, the planning model and one search (``uamopt plan``, ``network``,
#: ``reproduce``'s track stages). The fixed part is the interpreter, the libraries (numba's and
#: cvxpy's for a plan) and the city. Fitted on the peak RSS of the whole command, paper case,
#: ``--no-figures``, at 10 m and 5 m cells (4.05 M and 32.4 M cells; tests/benchmarks/bench_planning.py
#: row (vi) prints each estimate beside its measured peak): ``plan`` 0.33 and 0.90 GB, ``risk`` 0.30
#: and 1.55 GB; the per-cell parts are rounded up, so the estimates lie a few per cent above the peaks.
MEMORY_MODEL = {"risk": (120 * 2**20, 50), "plan": (255 * 2**20, 23)}


def memory_limit_bytes(limit_gb: float | None = None) -> int:
    """``limit_gb`` (``grid.memory_limit_gb``) in bytes, or 80 % of this machine's physical memory,
    within the process's address-space limit (``ulimit -v``, less what is mapped already) when one is set."""
    if limit_gb is not None:
        return int(limit_gb * 2**30)
    import os

    try:
        limit = int(0.8 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # not a POSIX machine: 8 GB
        limit = 8 * 2**30
    return min(limit, _address_space_left())


def _address_space_left() -> int:
    """Bytes the address-space limit (RLIMIT_AS, ``ulimit -v``) leaves beyond what this process has
    mapped, 80 % of it; unlimited (a huge number) when no limit is set or it cannot be read."""
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft == resource.RLIM_INFINITY:
            return 2**62
        with open("/proc/self/statm", encoding="ascii") as fh:
            mapped = int(fh.read().split()[0]) * resource.getpagesize()
    except (ImportError, OSError, ValueError, IndexError):
        return 2**62
    return max(int(0.8 * (soft - mapped)), 0)


def gigabytes(n_bytes: float) -> str:
    """``n_bytes`` in GB (2³⁰ bytes) for an error line, one decimal; three digits and an exponent when huge.

    >>> gigabytes(81_000_000_000), gigabytes(1e305)
    ('75.4', '9.31e+295')
    """
    gb = n_bytes / 2**30
    return f"{gb:.1f}" if gb < 1e6 else f"{gb:.3g}"


def memory_estimate(cells: float, use: str = "risk") -> float:
    """The peak memory, bytes, of a run on a grid of ``cells`` cells (:data:`MEMORY_MODEL`).

    >>> round(memory_estimate(32_400_000, "plan") / 2**30, 2)  # the paper case at 5 m cells
    0.94
    """
    fixed, per_cell = MEMORY_MODEL[use]
    return fixed + per_cell * cells


def check_memory(cell, extent, limit_bytes: int, use: str = "risk") -> None:
    """Refuse a grid whose run (``use``: :data:`MEMORY_MODEL`) would need more than ``limit_bytes``,
    before anything is allocated. The count is a float, so a tiny cell in a large extent (1e300
    cells) is refused, not an overflow."""
    cells = 1.0
    for e, c in zip(extent, cell, strict=False):
        cells *= max(math.floor(e / c + 1e-9), 0) if math.isfinite(e / c) else math.inf
    need = memory_estimate(cells, use)
    if need > limit_bytes:
        count = f"{int(cells):,}" if cells < 1e15 else f"{cells:.3g}"
        raise GridError(
            f"a grid of {count} cells needs about {gigabytes(need)} GB, more than the limit of {gigabytes(limit_bytes)} GB",
            "grid.cell / grid.extent", "use larger cells or a smaller extent, or raise grid.memory_limit_gb")


def file_grid(extent, cell, memory_limit_gb: float | None, source: str) -> AirspaceGrid:
    """:func:`build_grid` on the cells named by an input file (``flights.json``, ``network.json``):
    a grid too large for memory is that file's fault, and the error says so."""
    from uamopt.errors import InputFileError

    try:
        return build_grid(extent, cell, memory_limit_gb=memory_limit_gb)
    except GridError as exc:
        raise InputFileError(f"the file's cell {tuple(float(c) for c in cell)} m: {exc.what}", source,
                             "give 'cell' as the tracks were planned (e.g. [50, 50, 30]) or raise grid.memory_limit_gb") from None


def build_grid(extent, cell, *, memory_limit_gb: float | None = None, use: str = "risk") -> AirspaceGrid:
    """The grid of whole ``cell``-sized cells inside [0, x_max] × [0, y_max] × [0, z_max] = ``extent``.

    The scenario's grid (its extent defaulting to the city source's) is
    :func:`uamopt.pipeline.scenario_grid`.

    Raises
    ------
    GridError
        The grid holds no cell, or its run (``use``: ``"risk"`` or ``"plan"``, :data:`MEMORY_MODEL`)
        would need more memory than ``memory_limit_gb`` (default: 80 % of this machine's memory; a
        number of GB in (0, 1e6], as ``grid.memory_limit_gb``).
    ValueError
        ``use`` is neither ``"risk"`` nor ``"plan"``.

    Examples
    --------
    >>> build_grid((2500, 4500, 360), (50, 50, 30)).shape
    (50, 90, 12)
    """
    from uamopt.bounds import MAX_COORD_M, Range, check_cell, check_number, shown

    if not isinstance(use, str) or use not in MEMORY_MODEL:
        raise ValueError(f"build_grid(): use must be one of {', '.join(map(repr, MEMORY_MODEL))}, got {shown(use)}")
    if memory_limit_gb is not None:
        check_number(memory_limit_gb, "memory_limit_gb", "build_grid(memory_limit_gb=...)",
                     "give gigabytes, as grid.memory_limit_gb, or None for 80 % of this machine's memory",
                     Range(0.0, 1e6, lo_open=True), GridError)
    cell = check_cell(cell, "build_grid(cell=...)", "give three cell sizes in metres, each > 0, e.g. (50, 50, 30)", GridError)
    if not (isinstance(extent, (list, tuple)) and len(extent) == 3 and all(Range(0.0, MAX_COORD_M).holds(e) for e in extent)):
        raise GridError(f"the extent must be three sizes (x_max, y_max, z_max) in [0, {MAX_COORD_M:g}] m, got {shown(extent)}",
                        "build_grid(extent=...)", "give e.g. (2500, 4500, 360)")
    check_memory(cell, extent, memory_limit_bytes(memory_limit_gb), use)
    return AirspaceGrid.from_extent(cell, extent)
