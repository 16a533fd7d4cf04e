"""Defaults of the BlueSky export and replay, apart so that the CLI's parser reads them without
importing numpy (``uamopt --help`` stays fast)."""

DEFAULT_BANK_DEG = 45.0  # bank limit of the designed trajectory, degrees (docs/export.md)
DEFAULT_DT_S = 0.05  # BlueSky clock step, s
TRAJECTORIES = ("designed", "waypoints")
DEFAULT_TRAJECTORY = "designed"
DEFAULT_BUDGET_H_M = 10.0  # e_h, m: paper case, designed trajectory ≤ 7.81 m + BlueSky ≤ 1.63 m (docs/export.md)
DEFAULT_BUDGET_V_M = 2.0  # e_v: largest vertical deviation allowed from the plan, m
