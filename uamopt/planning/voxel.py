"""Moving AI 3-D voxel benchmarks as planner instances: an external check of the optimal cost.

Brewer and Sturtevant's voxel benchmarks (Brewer & Sturtevant, "Benchmarks for Pathfinding in 3D
Voxel Space", SoCS 2018; voxelised Warframe levels, published by the Moving AI Lab) give maps and
start/goal pairs with their optimal path lengths:

- ``.3dmap``: a header ``voxel X Y Z``, then one blocked voxel per line as ``x y z`` (0-based);
  every voxel not listed is free.
- ``.3dmap.3dscen``: ``version 1``, the map's name, then one row per problem
  ``sx sy sz gx gy gz optimal_cost ratio`` (ratio = optimal cost / the free-space
  length, the 3-D octile distance).

The costs assume 26-neighbour moves of Euclidean length (1, √2, √3), a diagonal move being legal
only when every voxel of its bounding box is free (no corner cutting) — the planner's own move
rule (docs/readings.md). A map is therefore an airspace of 1 m cells with risk 1 in every cell,
ω4 = 1, no buffer penalty and no transport cost (c_h = c_v = 0): a move costs
ω4·½(R_n + R_m)·d = d, and the search cost of :func:`~uamopt.planning.search.grid_search` is the
path's length.

Example
-------
>>> from uamopt.planning import grid_search
>>> voxels = read_voxel_map_text("voxel 3 2 1\\n1 1 0\\n")
>>> r = grid_search(voxel_problem(voxels), (0, 1, 0), (2, 1, 0))  # around the blocked voxel (1, 1, 0)
>>> r.cost  # 1 + 1 + 1 + 1: the diagonals would cut the voxel's corners
4.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uamopt.errors import InputFileError
from uamopt.planning.search import SearchProblem

MAP_FORMAT = "Moving AI .3dmap"
SCENARIO_FORMAT = "Moving AI .3dmap.3dscen"


@dataclass(frozen=True)
class VoxelMap:
    """A Moving AI voxel map: ``passable[x, y, z]`` (bool, shape (X, Y, Z))."""

    name: str
    passable: np.ndarray

    @property
    def size(self) -> tuple[int, int, int]:
        """(X, Y, Z), the header's voxel counts."""
        x, y, z = self.passable.shape
        return int(x), int(y), int(z)


@dataclass(frozen=True)
class VoxelScenario:
    """One benchmark problem of a ``.3dmap.3dscen`` file; start and goal are (x, y, z) voxels,
    which are also the (i, j, k) cells of :func:`voxel_problem`'s airspace."""

    start: tuple[int, int, int]
    goal: tuple[int, int, int]
    optimal_cost: float  # path length, voxels
    ratio: float  # optimal_cost / free-space (3-D octile) length, as printed in the file


def _first_bad_line(lines: list[str], first: int, ok) -> int:
    """The index of the first of ``lines[first:]`` for which ``ok(words)`` is false."""
    return next(n for n in range(first, len(lines)) if lines[n].split() and not ok(lines[n].split()))


def _is_int(word: str) -> bool:
    try:
        int(word)
    except ValueError:
        return False
    return True


def read_voxel_map_text(text: str, name: str = "<3dmap>") -> VoxelMap:
    """Parse the text of a ``.3dmap`` file. Raises InputFileError when it is malformed."""
    lines = text.splitlines()
    header = lines[0].split() if lines else []
    if len(header) != 4 or header[0] != "voxel" or not all(_is_int(w) and int(w) > 0 for w in header[1:]):
        raise InputFileError(f"the first line of {name} is not 'voxel X Y Z': {(lines[0] if lines else '')!r}",
                             MAP_FORMAT, "the header gives the three voxel counts, positive integers")
    size = tuple(int(w) for w in header[1:])
    words = [line.split() for line in lines[1:]]
    rows = [w for w in words if w]
    if any(len(w) != 3 for w in rows):
        n = _first_bad_line(lines, 1, lambda w: len(w) == 3)
        raise InputFileError(f"line {n + 1} of {name} is not a voxel 'x y z': {lines[n]!r}", MAP_FORMAT,
                             "give one blocked voxel per line as three integers")
    try:
        blocked = np.array(rows, dtype=np.int64).reshape(-1, 3)
    except ValueError:
        n = _first_bad_line(lines, 1, lambda w: all(_is_int(v) for v in w))
        raise InputFileError(f"line {n + 1} of {name} is not a voxel 'x y z': {lines[n]!r}", MAP_FORMAT,
                             "give one blocked voxel per line as three integers") from None
    outside = ((blocked < 0) | (blocked >= np.asarray(size))).any(axis=1)
    if outside.any():
        n = _first_bad_line(lines, 1, lambda w: all(0 <= int(v) < s for v, s in zip(w, size, strict=True)))
        raise InputFileError(f"voxel {tuple(int(v) for v in blocked[np.argmax(outside)])} on line {n + 1} of {name} "
                             f"lies outside the map of {size[0]} x {size[1]} x {size[2]} voxels", MAP_FORMAT,
                             "coordinates are 0-based and below the header's counts")
    passable = np.ones(size, dtype=bool)
    passable[tuple(blocked.T)] = False
    return VoxelMap(name=name, passable=passable)


def read_voxel_map(path: str | Path) -> VoxelMap:
    """Read a ``.3dmap`` file (Moving AI voxel format)."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"map file not found: {path}", MAP_FORMAT, "give the path of a .3dmap file")
    return read_voxel_map_text(path.read_text(encoding="latin-1"), name=path.name)


def read_voxel_scenarios_text(text: str, name: str = "<3dscen>") -> list[VoxelScenario]:
    """Parse the text of a ``.3dmap.3dscen`` file: one :class:`VoxelScenario` per row, in file order."""
    lines = text.splitlines()
    if not lines or not lines[0].startswith("version"):
        raise InputFileError(f"the first line of {name} is not 'version 1': {(lines[0] if lines else '')!r}",
                             SCENARIO_FORMAT, "the file starts with 'version 1' and the map's name")
    if len(lines) < 2 or len(lines[1].split()) != 1:
        raise InputFileError(f"line 2 of {name} is not a map name: {(lines[1] if len(lines) > 1 else '')!r}",
                             SCENARIO_FORMAT, "the file starts with 'version 1' and the map's name")
    rows = []
    for n, line in enumerate(lines[2:], start=3):
        fields = line.split()
        if not fields:
            continue
        try:
            if len(fields) != 8:
                raise ValueError
            sx, sy, sz, gx, gy, gz = (int(v) for v in fields[:6])
            cost, ratio = float(fields[6]), float(fields[7])
            if not (math.isfinite(cost) and cost >= 0):
                raise ValueError
        except ValueError:
            raise InputFileError(f"line {n} of {name} is not a scenario row: {line!r}", SCENARIO_FORMAT,
                                 "rows are 'sx sy sz gx gy gz optimal_cost ratio'") from None
        rows.append(VoxelScenario((sx, sy, sz), (gx, gy, gz), cost, ratio))
    return rows


def read_voxel_scenarios(path: str | Path) -> list[VoxelScenario]:
    """Read a ``.3dmap.3dscen`` file: one :class:`VoxelScenario` per benchmark problem, in file order."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"scenario file not found: {path}", SCENARIO_FORMAT, "give the path of a .3dmap.3dscen file")
    return read_voxel_scenarios_text(path.read_text(encoding="latin-1"), name=path.name)


def voxel_problem(voxel_map: VoxelMap) -> SearchProblem:
    """The map as an airspace whose search cost is the path length.

    Shape (X, Y, Z), 1 m cells, risk 1 everywhere with ω4 = 1, no penalty, c_h = c_v = 0. The risk
    and penalty are uint8 (one byte a voxel; the search takes every product in float64).
    """
    passable = voxel_map.passable.copy()
    return SearchProblem(passable=passable, risk=np.ones(passable.shape, dtype=np.uint8),
                         penalty=np.zeros(passable.shape, dtype=np.uint8), cell=(1.0, 1.0, 1.0), w_risk=1.0, c_h=0.0,
                         c_v=0.0)
