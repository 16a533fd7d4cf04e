"""Exports of a schedule folder for other tools (docs/interfaces.md, docs/export.md).

    export_bluesky("out/sched")   # out/sched/bluesky.scn: a BlueSky scenario of the operated flights
    export_geojson("out/sched")   # tracks.geojson, vertiports.geojson, unsafe.geojson in WGS 84

The georeference of the local frame is :mod:`uamopt.export.frame`; the replay in BlueSky is
:func:`uamopt.sim.replay`.
"""

from uamopt.export.bluesky import export_bluesky
from uamopt.export.frame import LocalFrame, scenario_frame
from uamopt.export.geojson import export_geojson

__all__ = ["LocalFrame", "export_bluesky", "export_geojson", "scenario_frame"]
