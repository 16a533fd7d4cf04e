"""Independent checks of a schedule in an air-traffic simulator (docs/export.md).

    result = replay("out/sched")          # BlueSky, headless, fast time; needs uamopt[sim]
    result.los_count, result.near_pairs, result.flights   # also out/sched/replay.json, replay.png

BlueSky itself is imported only by the worker process (:mod:`uamopt.sim.worker`).
"""

from uamopt.sim.replay import ReplayResult, replay
from uamopt.sim.zone import ProtectedZone, protected_zone

__all__ = ["ProtectedZone", "ReplayResult", "protected_zone", "replay"]
