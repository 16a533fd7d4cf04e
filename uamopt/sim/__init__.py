"""Independent checks of a schedule in an air-traffic simulator (docs/export.md).

    result = replay("out/sched")          # BlueSky, headless, fast time; needs uamopt[sim]
    result.los_count, result.near_pairs, result.flights   # also out/sched/replay.json, replay.png

BlueSky itself is imported only by the worker process (:mod:`uamopt.sim.worker`). The protected
zone the replay checks is :mod:`uamopt.export.zone` (the BlueSky export writes it too).
"""

from uamopt.export.zone import ProtectedZone, protected_zone
from uamopt.sim.replay import ReplayResult, replay

__all__ = ["ProtectedZone", "ReplayResult", "protected_zone", "replay"]
