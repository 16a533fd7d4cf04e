"""A reference for the exports' coordinates, independent of uamopt and pyproj.

The synthetic city's local (0, 0) is documented at 118.77 E, 32.02 N (uamopt/export/frame.py).
To first order, y runs along the meridian (WGS 84 radius M at the anchor) and x along the
point's own parallel (radius N cos φ); over a few kilometres the transverse Mercator differs from
this by < 0.3 m (~3e-6 degrees).
"""

from __future__ import annotations

import math

import numpy as np

ANCHOR_LONLAT = (118.77, 32.02)
A, E2 = 6378137.0, 6.69437999014e-3  # WGS 84 semi-major axis, first eccentricity squared


def hand_lonlat(x, y, lon0: float = ANCHOR_LONLAT[0], lat0: float = ANCHOR_LONLAT[1]):
    """(lon, lat) in degrees of local points (x east, y north, m from the anchor)."""
    s = math.sin(math.radians(lat0))
    m = A * (1 - E2) / (1 - E2 * s * s) ** 1.5
    lat = lat0 + np.degrees(np.asarray(y, float) / m)
    s = np.sin(np.radians(lat))
    n = A / np.sqrt(1 - E2 * s * s)
    return lon0 + np.degrees(np.asarray(x, float) / (n * np.cos(np.radians(lat)))), lat


def hand_local(lon, lat, lon0: float = ANCHOR_LONLAT[0], lat0: float = ANCHOR_LONLAT[1]):
    """(x, y) in metres of points (lon, lat) in degrees: the inverse of :func:`hand_lonlat`."""
    s = math.sin(math.radians(lat0))
    m = A * (1 - E2) / (1 - E2 * s * s) ** 1.5
    lat = np.asarray(lat, float)
    s = np.sin(np.radians(lat))
    n = A / np.sqrt(1 - E2 * s * s)
    return np.radians(np.asarray(lon, float) - lon0) * n * np.cos(np.radians(lat)), np.radians(lat - lat0) * m
