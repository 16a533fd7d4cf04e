"""City layers from three sources that produce the same :class:`CityLayers`.

- ``synthetic``: a seeded Nanjing-like city covering the paper's case (``uamopt.city.synthetic``).
- ``osm``: a real city from an OpenStreetMap .pbf through pyrosm (``uamopt.city.osm``).
- ``dsm``: a GeoTIFF digital surface model through rasterio (``uamopt.city.dsm``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from uamopt.city.layers import CityLayers, VectorCity, rasterize_city

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario

__all__ = ["CityLayers", "VectorCity", "load_city", "rasterize_city", "source_extent"]


def source_extent(scenario: Scenario) -> tuple[float, float]:
    """(x_max, y_max) of the city source in the local frame, m, for a grid with no extent."""
    source = scenario.city.source
    if source == "synthetic":
        from uamopt.city.synthetic import synthetic_extent

        return synthetic_extent(scenario)
    if source == "osm":
        from uamopt.city.osm import load_osm

        return load_osm(scenario).extent
    from uamopt.city.dsm import dsm_extent

    return dsm_extent(scenario)


def load_city(scenario: Scenario, grid: AirspaceGrid) -> CityLayers:
    """The scenario's city layers on the grid's columns.

    Raises
    ------
    InputFileError
        A .pbf, GeoTIFF or GeoJSON named by the scenario is missing or unreadable.
    TypeError
        ``scenario`` is not a Scenario or ``grid`` not an AirspaceGrid.
    """
    from uamopt.checks import expect
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario

    expect(scenario, Scenario, "scenario", "load_city")
    expect(grid, AirspaceGrid, "grid", "load_city")
    source = scenario.city.source
    if source == "synthetic":
        from uamopt.city.synthetic import synthetic_city

        return rasterize_city(synthetic_city(scenario), grid, scenario.city)
    if source == "osm":
        from uamopt.city.osm import load_osm

        return rasterize_city(load_osm(scenario), grid, scenario.city)
    from uamopt.city.dsm import load_dsm

    return load_dsm(scenario, grid)
