"""Moving AI grid benchmarks as planner instances: an external check of the optimal cost.

Sturtevant's Moving AI Lab benchmarks (Sturtevant, "Benchmarks for Grid-Based Pathfinding",
IEEE TCIAIG 4(2), 2012) publish maps and start/goal pairs with their optimal octile lengths:

- ``.map``: ``type octile``, ``height H``, ``width W``, ``map``, then H rows of W characters;
  ``.``, ``G`` and ``S`` are passable, every other character is blocked. Row index = y,
  column index = x.
- ``.map.scen``: an optional ``version 1`` line, then tab-separated rows
  ``bucket map width height start_x start_y goal_x goal_y optimal_length``.

The lengths assume 8-neighbour moves (straight 1, diagonal √2) with no corner cutting — the
planner's own move rule (docs/readings.md). A map is therefore a one-layer airspace with 1 m cells,
no risk, no buffer penalty and a transport cost equal to the horizontal distance (c_h = 1,
c_v = 0): the search cost of :func:`~uamopt.planning.search.grid_search` is the octile length.

Example
-------
>>> from uamopt.planning import grid_search
>>> octile = read_map_text("type octile\\nheight 2\\nwidth 3\\nmap\\n...\\n.@.\\n")
>>> r = grid_search(movingai_problem(octile), (0, 1, 0), (2, 1, 0))  # around the wall at x=1, y=1
>>> r.cost  # 1 + 1 + 1 + 1: the diagonals would cut the wall's corners
4.0
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uamopt.errors import InputFileError
from uamopt.planning.search import SearchProblem

PASSABLE = frozenset(".GS")


@dataclass(frozen=True)
class OctileMap:
    """A Moving AI map: ``passable[x, y]`` (bool, shape (width, height))."""

    name: str
    passable: np.ndarray

    @property
    def width(self) -> int:
        return int(self.passable.shape[0])

    @property
    def height(self) -> int:
        return int(self.passable.shape[1])


@dataclass(frozen=True)
class ScenarioRow:
    """One benchmark problem of a ``.map.scen`` file; coordinates are (x, y) cell indices."""

    bucket: int
    map_name: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal_length: float  # octile length, cells

    def cells(self) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
        """Start and goal as (i, j, k) cells of :func:`movingai_problem`'s one-layer airspace."""
        return (*self.start, 0), (*self.goal, 0)


def read_map_text(text: str, name: str = "<map>") -> OctileMap:
    """Parse the text of an octile ``.map`` file. Raises InputFileError when it is malformed."""
    lines = text.splitlines()
    header: dict[str, str] = {}
    for n, line in enumerate(lines):
        words = line.split()
        if words == ["map"]:
            rows = lines[n + 1:]
            break
        if len(words) != 2:
            raise InputFileError(f"unexpected header line {n + 1} in {name}: {line!r}", "Moving AI .map",
                                 "the header is 'type octile', 'height H', 'width W', 'map'")
        header[words[0]] = words[1]
    else:
        raise InputFileError(f"no 'map' line in {name}", "Moving AI .map", "give an octile .map file")
    if header.get("type") != "octile":
        raise InputFileError(f"{name} has type {header.get('type')!r}", "Moving AI .map", "only 'type octile' maps are read")
    try:
        height, width = int(header["height"]), int(header["width"])
    except (KeyError, ValueError):
        raise InputFileError(f"{name} lacks an integer height or width", "Moving AI .map",
                             "give 'height H' and 'width W' lines") from None
    rows = [r.rstrip("\r\n") for r in rows[:height]]
    if len(rows) != height or any(len(r) != width for r in rows):
        raise InputFileError(f"{name} does not have {height} rows of {width} characters", "Moving AI .map",
                             "check the height and width lines against the grid")
    # rows are y, columns are x: transpose to passable[x, y]
    grid = np.frombuffer("".join(rows).encode("latin-1"), dtype=np.uint8).reshape(height, width)
    lookup = np.zeros(256, dtype=bool)
    lookup[[ord(c) for c in PASSABLE]] = True
    return OctileMap(name=name, passable=np.ascontiguousarray(lookup[grid].T))


def read_map(path: str | Path) -> OctileMap:
    """Read an octile ``.map`` file (Moving AI format)."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"map file not found: {path}", "Moving AI .map", "give the path of a .map file")
    return read_map_text(path.read_text(encoding="latin-1"), name=path.name)


def read_scenarios(path: str | Path) -> list[ScenarioRow]:
    """Read a ``.map.scen`` file: one :class:`ScenarioRow` per benchmark problem, in file order."""
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"scenario file not found: {path}", "Moving AI .map.scen", "give the path of a .map.scen file")
    rows = []
    for n, line in enumerate(path.read_text(encoding="latin-1").splitlines(), start=1):
        if not line.strip() or line.startswith("version"):
            continue
        fields = line.split("\t") if "\t" in line else line.split()
        try:
            if len(fields) != 9:
                raise ValueError
            bucket, width, height, sx, sy, gx, gy = (int(fields[i]) for i in (0, 2, 3, 4, 5, 6, 7))
            rows.append(ScenarioRow(bucket, fields[1], width, height, (sx, sy), (gx, gy), float(fields[8])))
        except ValueError:
            raise InputFileError(f"line {n} of {path.name} is not a scenario row: {line!r}", "Moving AI .map.scen",
                                 "rows are 'bucket map width height start_x start_y goal_x goal_y optimal_length'") from None
    return rows


def movingai_problem(octile: OctileMap) -> SearchProblem:
    """The map as a one-layer airspace whose search cost is the octile length.

    Shape (width, height, 1), 1 m cells, risk 0, no penalty, ω4 = 0, c_h = 1, c_v = 0.
    """
    passable = octile.passable[:, :, None].copy()
    zero = np.zeros(passable.shape)
    return SearchProblem(passable=passable, risk=zero, penalty=zero, cell=(1.0, 1.0, 1.0), w_risk=0.0,
                         c_h=1.0, c_v=0.0)
