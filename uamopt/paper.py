"""The paper's published values that uamopt's reports and figures set beside their own
(``uamopt reproduce``'s report.md, ``plot_sweep(table, "cell")``). One copy, used by both.

The paper: "Multi-Aircraft Scheduling Optimization in Urban Environments" (docs/readings.md).
"""

#: Table 2 (P_O -> P_D at 10 m cells): shortest, initial, equivalent and optimal track, per measure.
TABLE2 = {
    "operational risk": (196, 174, 174, 181),
    "transport cost (¥)": (27.1527, 32.7379, 32.0715, 30.8265),
    "waypoints": (386, 456, 453, 432),
    "computational time (s)": (68.71, 90.58, 101.96, 108.97),
}

#: Table 4, per cubic cell side (m): operational risk, transport cost (¥), waypoints, computing time (s).
TABLE4 = {10.0: (196.0, 27.1527, 386, 68.71), 5.0: (163.33, 25.7975, 636, 659.52)}

#: Table 3, per strategy: operated flights, cancelled flights, total delay (s).
TABLE3 = {"greedy": (109, 11, 2401), "soa": (117, 3, 1911), "ga": (114, 6, 2161)}


def table4_row(cell) -> tuple | None:
    """Table 4's row for a cell ``cell`` (a side in m, or three sides that are all equal), else None."""
    try:
        sides = {float(c) for c in cell} if isinstance(cell, (list, tuple)) else {float(cell)}
    except (TypeError, ValueError):
        return None
    return TABLE4.get(sides.pop()) if len(sides) == 1 else None
