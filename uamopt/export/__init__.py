"""Exports of a schedule folder for other tools (docs/interfaces.md, docs/export.md).

    export_bluesky("out/sched")   # out/sched/bluesky.scn: a BlueSky scenario of the operated flights
    export_geojson("out/sched")   # tracks, vertiports, unsafe .geojson in WGS 84; trips.kepler.json
    flyable_trajectory(waypoints, 25.0, 45.0)   # what the BlueSky export commands for one track

The georeference of the local frame is :mod:`uamopt.export.frame`; the replay in BlueSky is
:func:`uamopt.sim.replay`.
"""

from uamopt.lazy import lazy_getattr

#: public name -> module (imported on first access, PEP 562: ``uamopt --help`` loads none of them)
_LAZY = {"export_bluesky": "uamopt.export.bluesky", "LocalFrame": "uamopt.export.frame",
         "scenario_frame": "uamopt.export.frame", "export_geojson": "uamopt.export.geojson",
         "Trajectory": "uamopt.export.trajectory", "flyable_trajectory": "uamopt.export.trajectory"}
__all__ = sorted(_LAZY)
__getattr__ = lazy_getattr(__name__, _LAZY)
