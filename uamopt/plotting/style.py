"""The shared look of uamopt's figures: constants only.

Resolution and the page size, the data credit, the colours of the maps and sections, the white
halo behind labels drawn over cells, the largest map whose road columns are outlined and the
legend placed below a map. The figures and axes are laid out in :mod:`uamopt.plotting.layout`,
the shared drawing on an Axes is :mod:`uamopt.plotting.draw` and files are written by
:mod:`uamopt.plotting.output`.
"""

from __future__ import annotations

from matplotlib import patheffects

DPI = 110  # dots per inch of a saved PNG (a 14 × 8 in page is 1540 × 880 pixels)
FIGSIZE_IN = (14.0, 8.0)  # the page of the risk, tracks and network figures
OSM_CREDIT = "© OpenStreetMap contributors (ODbL)"

OBSTACLE_GREY = "#3d3d3d"  # cells inside or below a building (NaN risk)
BUILDING_GREY = "#1f1f1f"  # the true surface profile in a section
GROUND = "#efebe4"
OPEN_SPACE = "#b9dba0"  # parks and water
ROAD = "#8c8c8c"
NO_FLY = "#d62728"
BAND_GREEN = "#2ca02c"  # the altitude band of Eq. 14
BAND_TEXT = "#1a6e1a"
HALO = [patheffects.withStroke(linewidth=2.5, foreground="white")]
ROAD_OUTLINE_MAX_COLUMNS = 120  # columns across a map up to which road columns are outlined
# legends below a map, clear of its tick labels and x label (borderaxespad is in font sizes)
LEGEND_BELOW = {"loc": "upper center", "bbox_to_anchor": (0.5, 0.0), "borderaxespad": 3.4, "ncol": 2,
                "fontsize": 7, "frameon": False}
