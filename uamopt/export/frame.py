"""Where the local metric frame lies on the Earth: the georeference every export uses.

The model works in a local frame (docs/readings.md): x east, y north, z altitude above the ground
datum, metres. A :class:`LocalFrame` ties it to a projected CRS: local (x, y) = CRS (E − E₀, N − N₀)
with (E₀, N₀) = ``origin``, the CRS coordinates of the local (0, 0). Per city source:

- ``synthetic``: a transverse Mercator on WGS 84 whose origin is the documented anchor
  :data:`SYNTHETIC_ANCHOR_LONLAT` = (118.7700 E, 32.0200 N), the south-west corner of the domain
  in central Nanjing (the paper's case is Nanjing-like). The city itself is synthetic: the anchor
  only puts it on a map, with the scale of a real place.
- ``osm``: the loader's own transverse Mercator centred on the OpenStreetMap data, origin at the
  data's south-west corner (``uamopt.city.osm``).
- ``dsm``: the GeoTIFF's projected CRS, origin at the raster's (left, bottom) corner
  (``uamopt.city.dsm``).

``uamopt schedule`` records the frame in ``summary.json`` (key ``frame``, with the scenario file
and overrides under ``scenario``) so that a schedule folder can be exported alone. A folder
written before this key existed falls back to the synthetic anchor, and the exports say so.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import InputFileError

if TYPE_CHECKING:
    from uamopt.scenario import Scenario

SYNTHETIC_ANCHOR_LONLAT = (118.7700, 32.0200)  # degrees E, N: local (0, 0) of the synthetic city
_TMERC = "+proj=tmerc +lat_0={lat:.7f} +lon_0={lon:.7f} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"


@functools.lru_cache(maxsize=16)
def _transformers(crs: str):
    from pyproj import Transformer

    return (Transformer.from_crs(crs, "EPSG:4326", always_xy=True),
            Transformer.from_crs("EPSG:4326", crs, always_xy=True))


@dataclass(frozen=True)
class LocalFrame:
    """The local metric frame's place on the Earth.

    Attributes
    ----------
    crs : str
        A projected CRS in metres (PROJ string, EPSG code or WKT).
    origin : (float, float)
        The local (0, 0) in ``crs`` coordinates (E₀, N₀), m.
    source : str
        The city source the frame came from (``synthetic``, ``osm``, ``dsm``), or ``default``
        for a schedule folder that recorded none.

    Examples
    --------
    >>> f = synthetic_frame()
    >>> [round(float(v), 4) for v in f.to_lonlat(0.0, 0.0)]
    [118.77, 32.02]
    """

    crs: str
    origin: tuple[float, float]
    source: str

    def to_lonlat(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """WGS 84 (lon, lat), degrees, of local points (x, y), m."""
        inverse, _ = _transformers(self.crs)
        lon, lat = inverse.transform(np.asarray(x, float) + self.origin[0], np.asarray(y, float) + self.origin[1])
        return np.asarray(lon), np.asarray(lat)

    def from_lonlat(self, lon, lat) -> tuple[np.ndarray, np.ndarray]:
        """Local (x, y), m, of WGS 84 points (lon, lat), degrees."""
        _, forward = _transformers(self.crs)
        e, n = forward.transform(np.asarray(lon, float), np.asarray(lat, float))
        return np.asarray(e) - self.origin[0], np.asarray(n) - self.origin[1]

    def as_dict(self) -> dict:
        lon, lat = self.to_lonlat(0.0, 0.0)
        return {"crs": self.crs, "origin": list(self.origin), "source": self.source,
                "origin_lonlat": [float(lon), float(lat)],
                "axes": "x east, y north (m from origin); z altitude above the ground datum (m)"}

    @classmethod
    def from_dict(cls, raw: dict, where: str) -> LocalFrame:
        from pyproj.exceptions import CRSError

        from uamopt.bounds import Range, check_number

        try:
            origin = tuple(check_number(v, "the frame's origin", where, "rewrite the folder with uamopt schedule",
                                        Range(-1e8, 1e8)) for v in raw["origin"][:2])  # projected metres
            frame = cls(crs=str(raw["crs"]), origin=(origin[0], origin[1]), source=str(raw.get("source", "")))
            _transformers(frame.crs)
        except (KeyError, TypeError, ValueError, IndexError, CRSError) as exc:
            raise InputFileError(f"malformed 'frame': {exc.__class__.__name__}: {exc}", where,
                                 "rewrite the folder with uamopt schedule") from None
        return frame


def synthetic_frame(source: str = "synthetic") -> LocalFrame:
    """The documented anchor of the synthetic city (:data:`SYNTHETIC_ANCHOR_LONLAT`)."""
    lon, lat = SYNTHETIC_ANCHOR_LONLAT
    return LocalFrame(crs=_TMERC.format(lat=lat, lon=lon), origin=(0.0, 0.0), source=source)


def scenario_frame(scenario: Scenario) -> LocalFrame:
    """The local frame of the scenario's city source (see the module docstring).

    Raises
    ------
    InputFileError, ScenarioError
        The .pbf or GeoTIFF named by the scenario is missing or unreadable.
    """
    source = scenario.city.source
    if source == "synthetic":
        return synthetic_frame()
    if source == "osm":
        from uamopt.city.osm import load_osm

        city = load_osm(scenario)  # cached: the grid and the city loaded it already
        _, forward = _transformers(city.crs)
        e0, n0 = forward.transform(*city.origin)  # the loader records the origin as (lon, lat)
        return LocalFrame(crs=city.crs, origin=(float(e0), float(n0)), source="osm")
    from uamopt.city.dsm import dsm_frame

    crs, left, bottom = dsm_frame(scenario)
    return LocalFrame(crs=crs, origin=(left, bottom), source="dsm")


def schedule_provenance(scenario: Scenario, overrides: list[str] | None = None) -> dict:
    """The ``frame`` and ``scenario`` keys ``uamopt schedule`` adds to summary.json."""
    source = scenario.source
    # absolute as the user named it: models/paper_case.toml stays so, not the package file its link leads to
    file = os.path.abspath(source) if source and not source.startswith("<") else None
    return {"frame": scenario_frame(scenario).as_dict(),
            "scenario": {"name": scenario.name, "file": file, "set": list(overrides or [])}}
