"""Single-aircraft track planning (Sec. 4.2, 5.1): risk-aware A* with a safety buffer, the exact
equivalent track and smoothing. ``planning_model`` → ``plan_track`` / ``plan_network``."""

from uamopt.planning.problem import PlanningModel, planning_model
from uamopt.planning.search import SearchProblem, SearchResult, grid_search
from uamopt.planning.tracks import STAGES, TrackPlan, TrackStage, TrackWeightsWarning, plan_track

__all__ = ["STAGES", "PlanningModel", "SearchProblem", "SearchResult", "TrackPlan", "TrackStage",
           "TrackWeightsWarning", "grid_search", "plan_track", "planning_model"]
