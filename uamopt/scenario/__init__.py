"""Scenarios: typed, validated parameters, loaded from TOML.

- :mod:`uamopt.scenario.schema`: every key with its symbol, unit, equation, default (Table B.3)
  and range; the frozen models ``Scenario``, ``GridConfig``, ``CityConfig``, ...
- :mod:`uamopt.scenario.loading`: ``load_scenario(path, overrides)``, ``--set KEY=VALUE``
  overrides, ``key_ranges()``, and the one-line error of a value that does not validate.
"""

from uamopt.scenario.loading import apply_overrides, key_ranges, load_scenario, parse_override, validate
from uamopt.scenario.schema import (
    MAX_ALTITUDE_M,
    MAX_COUNT,
    AircraftConfig,
    CityConfig,
    GridConfig,
    NetworkConfig,
    Number,
    RiskConfig,
    Scenario,
    ScheduleConfig,
    TracksConfig,
    Vertiport,
    Whole,
    random_vertiports,
)

__all__ = ["MAX_ALTITUDE_M", "MAX_COUNT", "AircraftConfig", "CityConfig", "GridConfig", "NetworkConfig", "Number",
           "RiskConfig", "Scenario", "ScheduleConfig", "TracksConfig", "Vertiport", "Whole", "apply_overrides",
           "key_ranges", "load_scenario", "parse_override", "random_vertiports", "validate"]
