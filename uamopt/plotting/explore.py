"""An offline, interactive 3-D view of a schedule: the city, the unsafe airspace, the tracks and the
flights played back at their scheduled times (``uamopt view DIR``, :func:`explore`).

The view is a plotly figure written as one self-contained HTML file: plotly.js is inlined
(``include_plotlyjs=True``, about 4.8 MB), so the file opens from disk with no network. Chosen by
measurement (docs/export.md): plotly's inline bundle makes no remote reference, while pydeck's
offline HTML still loads a map library and four stylesheets from the network, and kepler.gl's from
a CDN with a token.

What it draws, from the schedule folder and the risk field of its recorded scenario (or ``risk=``
a risk.npz, as ``uamopt export geojson``):

- buildings: one box per building column (the cell footprint, up to its height), one mesh;
- the unsafe airspace (Eq. 9: risk above R_0 or no-fly, obstacles left out), one trace per
  altitude layer, hidden at first and toggled in the legend; no-fly columns on the ground;
- vertiports with their names, and every track (one line per route and direction);
- the playback: the airborne aircraft at every ``step_s`` of the clock (plotly frames), a time
  slider, play and pause, three playback speeds, and colour by route or by delay (two traces, one
  shown at a time). Hovering an aircraft shows its flight, aircraft, route, delay and altitude;
  flights in a pair the independent verifier (``uamopt verify``) rejects are drawn red and
  larger; the cancelled flights are listed under the title.

Positions follow the plan exactly (Eq. 31: each waypoint at its time from the departure, the
vertical phases at their rate; :func:`uamopt.schedule.flights.waypoint_times_s`), linear between.
"""

from __future__ import annotations

import html
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uamopt.errors import UamoptError
from uamopt.optional import need

#: at most this many frames: the step grows for long schedules (a day at 10 s would be 8,640)
MAX_FRAMES = 720
DEFAULT_STEP_S = 10.0
PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
           "#7f7f7f", "#aec7e8", "#ffbb78", "#98df8a", "#c5b0d5", "#c49c94", "#f7b6d2", "#9edae5"]
CONFLICT_COLOUR = "#d62728"
BUILDING_COLOUR = "#8c8c8c"
UNSAFE_COLOUR = "#e6550d"
SPEEDS = {"1×": 120, "4×": 30, "16×": 8}  # frame durations, ms
AIRCRAFT_SIZE = 10  # px; a flight in a pair the verifier rejects is drawn 5 px larger
SCENE = {"aspectmode": "data", "camera": {"eye": {"x": 0.7, "y": -2.6, "z": 2.6}},  # from the south, above: the city whole
         "xaxis": {"title": {"text": "x (m)"}}, "yaxis": {"title": {"text": "y (m)"}},
         "zaxis": {"title": {"text": "z (m)"}}}


@dataclass
class Explorer:
    """The view, shown inline in Jupyter and written by :meth:`save`: ``spec`` is the plotly figure
    as plain JSON-ready data (written without plotly's per-attribute validation, which took most of
    a minute for 1,000 flights); :attr:`figure` builds the plotly Figure from it on demand."""

    spec: dict
    title: str

    @property
    def figure(self):
        """The view as a ``plotly.graph_objects.Figure`` (validated; built on each call)."""
        import plotly.graph_objects as go

        return go.Figure(self.spec)

    def _html(self, full: bool) -> str:
        import plotly.io as pio

        return pio.to_html(self.spec, include_plotlyjs=True, full_html=full, auto_play=False, validate=False,
                           config={"displaylogo": False})

    def save(self, path: str | Path) -> Path:
        """Write the view as one self-contained HTML file (plotly.js inlined: no network needed)."""
        from uamopt.outputs import atomic_write

        path = Path(path)
        text = self._html(True).replace("<head>", f"<head><title>{html.escape(self.title)}</title>", 1)
        atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"))
        return path

    def _repr_html_(self) -> str:  # Jupyter: inline, offline (plotly.js in the cell's output)
        return self._html(False)


def _typed(a, dtype: str) -> dict:
    """An array as plotly.js's typed-array spec (little-endian, base64): float32 positions take
    5.3 characters a number instead of JSON's 10 to 18."""
    import base64

    raw = np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes()
    return {"dtype": dtype, "bdata": base64.b64encode(raw).decode("ascii")}


def _plain(traces: list) -> list[dict]:
    """plotly graph objects as the JSON plotly writes for them (arrays as typed-array specs)."""
    import json

    import plotly.io as pio

    return json.loads(pio.to_json({"data": traces, "layout": {}}, validate=False, engine="json"))["data"] if traces else []


def _flight_positions(operated, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(positions (len(t), 3), airborne mask) of one operated flight at clock times ``t``."""
    from uamopt.schedule.flights import waypoint_times_s

    f = operated.flight
    wp = np.asarray(f.waypoints, float)
    times = operated.departure_s + waypoint_times_s(wp, f.speed_mps, f.vertical_rate_mps)
    on = (t >= times[0]) & (t <= times[-1])
    tt = np.clip(t, times[0], times[-1])
    return np.column_stack([np.interp(tt, times, wp[:, k]) for k in range(3)]), on


def _boxes(x0, x1, y0, y1, top) -> dict:
    """One Mesh3d's vertices and triangles of axis-aligned boxes from z = 0 to ``top``."""
    n = len(top)
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    xs = np.where(corners[:, 0] == 0, x0[:, None], x1[:, None]).ravel()
    ys = np.where(corners[:, 1] == 0, y0[:, None], y1[:, None]).ravel()
    zs = np.where(corners[:, 2] == 0, 0.0, top[:, None]).ravel()
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                      [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    tri = (faces[None, :, :] + 8 * np.arange(n)[:, None, None]).reshape(-1, 3)
    return {"x": xs, "y": ys, "z": zs, "i": tri[:, 0], "j": tri[:, 1], "k": tri[:, 2]}


def _rejected_flights(path: Path, ids: set[str]) -> set[str]:
    """Flights of every pair the independent verifier rejects in the folder: its lines that name
    two or more flights (a conflict, a pad over capacity, a spacing)."""
    from uamopt.schedule.verify import verify_dir

    out: set[str] = set()
    for line in verify_dir(path):
        named = set(re.findall(r"[\w.-]+", line)) & ids
        if len(named) >= 2:
            out |= named
    return out


def _city_traces(field, go) -> list:
    """Buildings, no-fly columns and one unsafe trace per layer from a risk field (arrays)."""
    x, y, z = field["x"], field["y"], field["z"]
    dx, dy, dz = field["cell"]
    traces = []
    height = field["building_height"]
    ix, iy = np.nonzero(height > 0)
    if len(ix):
        box = _boxes(x[ix] - dx / 2, x[ix] + dx / 2, y[iy] - dy / 2, y[iy] + dy / 2, height[ix, iy])
        traces.append(go.Mesh3d(**box, color=BUILDING_COLOUR, opacity=1.0, flatshading=True, name="buildings",
                                showlegend=True, hoverinfo="skip", lighting={"ambient": 0.6, "diffuse": 0.6}))
    nofly = field.get("no_fly")
    if nofly is not None and nofly.any():
        ix, iy = np.nonzero(nofly)
        traces.append(go.Scatter3d(x=x[ix], y=y[iy], z=np.zeros(len(ix)), mode="markers", name="no-fly zone",
                                   marker={"size": 3, "color": "#000000", "symbol": "square"}, hoverinfo="skip"))
    unsafe = field["unsafe"] & ~field["obstacle"]
    for k in range(unsafe.shape[2]):
        ix, iy = np.nonzero(unsafe[:, :, k])
        if not len(ix):
            continue
        traces.append(go.Scatter3d(
            x=x[ix], y=y[iy], z=np.full(len(ix), z[k]), mode="markers", visible="legendonly",
            name=f"unsafe {z[k] - dz / 2:.0f}–{z[k] + dz / 2:.0f} m", legendgroup="unsafe",
            marker={"size": 2, "color": UNSAFE_COLOUR, "opacity": 0.35, "symbol": "square"}, hoverinfo="skip"))
    return traces


def _vertiports(ports: dict, go) -> list:
    """One marker trace of the vertiports (name -> [x, y, z]), labelled."""
    if not ports:
        return []
    names = sorted(ports)
    xyz = np.array([ports[n] for n in names])
    return [go.Scatter3d(x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], mode="markers+text", name="vertiports", text=names,
                         textposition="top center", marker={"size": 6, "color": "#000000", "symbol": "diamond"},
                         hovertemplate="vertiport %{text}<extra></extra>")]


def _field_arrays(f) -> dict:
    """The arrays the city traces need, from a RiskField."""
    return {"unsafe": f.unsafe, "obstacle": f.obstacle, "x": f.grid.x, "y": f.grid.y, "z": f.grid.z,
            "cell": tuple(f.grid.cell), "building_height": f.city.building_height, "no_fly": f.city.no_fly}


def _risk_arrays(folder, risk, scenario, overrides) -> dict:
    """The arrays the city traces need, from a risk.npz or the folder's recorded scenario."""
    if risk is not None:
        from uamopt.io import read_npz

        data = read_npz(Path(risk), "give a risk.npz written by uamopt risk",
                        ("unsafe", "obstacle", "x", "y", "z", "cell", "building_height"))
        return {k: np.asarray(data[k]) for k in ("unsafe", "obstacle", "x", "y", "z", "building_height")} | {
            "cell": tuple(float(c) for c in data["cell"]),
            "no_fly": np.asarray(data["no_fly"]) if "no_fly" in data else None}
    from uamopt.export.folder import recorded_scenario
    from uamopt.pipeline import compute_risk

    return _field_arrays(compute_risk(recorded_scenario(folder, scenario, overrides)))


STAGE_COLOUR = {"shortest": "#7f7f7f", "initial": "#1f77b4", "equivalent": "#ff7f0e", "optimal": "#2ca02c"}


def _read_json(path: Path) -> dict:
    from uamopt.bounds import read_json
    from uamopt.errors import InputFileError

    # malformed, not UTF-8, nested too deeply, a number beyond Python's limit: one line each
    doc = read_json(path, path.name, str(path), f"the {path.name} uamopt wrote")
    if not isinstance(doc, dict):
        raise InputFileError(f"{path.name} is not a JSON object", str(path), "rewrite it with uamopt")
    return doc


def _mapping(doc: dict, key: str, where: Path) -> dict:
    """``doc[key]``: a JSON object (name -> entry), ``{}`` when absent or null."""
    from uamopt.bounds import shown
    from uamopt.errors import InputFileError

    value = doc.get(key) or {}
    if not isinstance(value, dict):
        raise InputFileError(f"'{key}' in {where.name} is not a JSON object (name -> entry), got {shown(value)}",
                             str(where), "rewrite it with uamopt")
    return value


def _polyline(points, where: Path) -> np.ndarray:
    from uamopt.errors import InputFileError

    try:
        wp = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        wp = np.zeros((0, 0))
    if wp.ndim != 2 or wp.shape[1] != 3 or len(wp) < 2 or not np.isfinite(wp).all():
        raise InputFileError("a track's waypoints are not a list of at least two finite [x, y, z]", str(where),
                             "rewrite it with uamopt")
    return wp


def _static_view(here: Path, risk, scenario, overrides, city: bool, go) -> Explorer:
    """A folder of ``uamopt risk``, ``plan``, ``network`` or ``reproduce``: the city, the unsafe
    airspace and the tracks it holds (the four stages of Table 2, the network's routes), no playback."""
    from uamopt.bounds import shown
    from uamopt.errors import InputFileError

    tracks = here / "tracks.json"
    network = here / "network.json"
    npz = here / "risk.npz"
    if not (tracks.is_file() or network.is_file() or npz.is_file()):
        raise InputFileError("no schedule.csv, network.json, tracks.json or risk.npz in the folder", str(here),
                             "give a folder written by uamopt risk, plan, network, schedule or reproduce")
    lines, ports = [], {}
    if network.is_file():
        for name, r in _mapping(_read_json(network), "routes", network).items():
            wp = _polyline(r.get("waypoints") if isinstance(r, dict) else None, network)
            lines.append((f"track {name}", wp, None))
            a, _, b = str(name).partition("-")
            ports.setdefault(a, wp[0])
            ports.setdefault(b, wp[-1])
    record = {}
    if tracks.is_file():
        doc = _read_json(tracks)
        record = doc.get("scenario") if isinstance(doc.get("scenario"), dict) else {}
        for stage, body in _mapping(doc, "stages", tracks).items():
            lines.append((f"{stage} track", _polyline(body.get("waypoints") if isinstance(body, dict) else None, tracks),
                          STAGE_COLOUR.get(stage)))
    traces = []
    if city:
        if risk is None and npz.is_file():
            risk = npz
        if risk is None and scenario is None and not isinstance(record.get("file") or "", str):
            raise InputFileError(f"the recorded scenario file is not a path, got {shown(record['file'])}", str(tracks),
                                 "rewrite it with uamopt plan, or pass --scenario FILE, --risk risk.npz or --no-city")
        if risk is None and scenario is None and not record.get("file"):
            raise InputFileError("the folder records no scenario file for the city", str(here),
                                 "pass --scenario FILE (and its --set keys), --risk risk.npz, or --no-city")
        if risk is not None:
            arrays = _risk_arrays(None, risk, None, None)
        else:
            from uamopt.pipeline import compute_risk
            from uamopt.scenario import load_scenario

            arrays = _field_arrays(compute_risk(load_scenario(scenario or record["file"], list(overrides or []))))
        traces += _city_traces(arrays, go)
    for n, (name, wp, colour) in enumerate(lines):
        traces.append(go.Scatter3d(x=wp[:, 0], y=wp[:, 1], z=wp[:, 2], mode="lines", name=name, legendgroup="tracks",
                                   line={"color": colour or PALETTE[n % len(PALETTE)], "width": 4},
                                   hovertemplate=f"{html.escape(name)}<br>z %{{z:.0f}} m<extra></extra>"))
    traces += _vertiports(ports, go)
    what = "network" if network.is_file() else "plan" if tracks.is_file() else "risk field"
    title = f"uamopt {what} {here.name}: {len(lines)} tracks"
    layout = {"title": {"text": html.escape(title), "x": 0.01}, "scene": SCENE,
              "legend": {"itemsizing": "constant", "x": 1.0, "xanchor": "left", "y": 1.0},
              "margin": {"l": 0, "r": 230, "t": 60, "b": 0}, "height": 820, "width": 1280,
              "meta": {"uamopt": {"kind": what, "tracks": [name for name, _, _ in lines]}}}
    return Explorer(spec={"data": _plain(traces), "layout": layout}, title=title)


def explore(path, schedule=None, *, field=None, risk: str | Path | None = None, scenario: str | None = None,
            overrides: list[str] | None = None, step_s: float | None = None, city: bool = True) -> Explorer:
    """The interactive 3-D view of the schedule folder ``path`` (module docstring), or of a
    schedule in memory: ``explore(problem, schedule, field=field)``.

    Parameters
    ----------
    path : folder written by ``uamopt schedule`` (or by ``risk``, ``plan``, ``network``,
        ``reproduce``: the city and the tracks it holds, no playback), or a SchedulingProblem (then ``schedule`` is its
        Schedule, written to a temporary folder and read back as ``uamopt view`` reads it).
    field : the RiskField of the schedule's scenario (in memory; instead of ``risk``).
    risk : a risk.npz of the same scenario, instead of recomputing the field from the recorded one.
    scenario, overrides : the scenario file (and ``--set`` keys) when the folder records none.
    step_s : the playback's clock step, s (default 10 s, larger where the schedule would need
        more than ``MAX_FRAMES`` frames).
    city : draw the buildings and the unsafe airspace (needs the risk field).

    Returns
    -------
    Explorer
        ``.figure`` (plotly), ``.save("view.html")``; displays inline in Jupyter.

    Examples
    --------
    >>> view = ua.plotting.explore("out/sched")   # doctest: +SKIP
    >>> view.save("out/sched/view.html")           # doctest: +SKIP
    >>> ua.plotting.explore(problem, schedule, field=field)   # in a notebook  # doctest: +SKIP
    """
    from uamopt.schedule.model import SchedulingProblem

    if isinstance(path, SchedulingProblem) or field is not None:
        import tempfile

        with tempfile.TemporaryDirectory(prefix="uamopt-view-") as tmp:
            if isinstance(path, SchedulingProblem):
                if schedule is None:
                    raise TypeError("explore(problem, schedule): schedule is required with a problem")
                from uamopt.schedule import write_schedule

                write_schedule(Path(tmp) / "schedule", path, schedule)
                path = Path(tmp) / "schedule"
            if field is not None:
                field.save_npz(Path(tmp) / "risk.npz")
                risk = Path(tmp) / "risk.npz"
            return explore(path, risk=risk, scenario=scenario, overrides=overrides, step_s=step_s, city=city)
    if schedule is not None:
        raise TypeError("explore(folder): a schedule is given only with its problem, explore(problem, schedule)")
    go = need("plotly.graph_objects", extra="view", what="the 3-D view (uamopt view, explore)")

    from uamopt.export.folder import read_schedule_folder

    if step_s is not None and not (isinstance(step_s, (int, float)) and math.isfinite(step_s) and step_s > 0):
        raise UamoptError(f"the playback step must be a positive number of seconds, got {step_s!r}", "--step",
                          "give e.g. 10")
    here = Path(path)
    if here.is_dir() and not (here / "schedule.csv").is_file():
        return _static_view(here, risk, scenario, overrides, city, go)
    folder = read_schedule_folder(path)
    traces = _city_traces(_risk_arrays(folder, risk, scenario, overrides), go) if city else []
    flights = folder.flights.flights
    routes = sorted({f.route for f in flights})
    colour = {r: PALETTE[i % len(PALETTE)] for i, r in enumerate(routes)}
    seen: set[str] = set()
    for f in flights:  # one line per route and direction
        if f.route in seen:
            continue
        seen.add(f.route)
        wp = np.asarray(f.waypoints, float)
        traces.append(go.Scatter3d(x=wp[:, 0], y=wp[:, 1], z=wp[:, 2], mode="lines", name=f"track {f.route}",
                                   legendgroup="tracks", line={"color": colour[f.route], "width": 3},
                                   hovertemplate=f"track {html.escape(f.route)}<br>z %{{z:.0f}} m<extra></extra>"))
    ports: dict[str, np.ndarray] = {}
    for f in flights:
        ports.setdefault(f.origin, np.asarray(f.waypoints[0], float))
        ports.setdefault(f.destination, np.asarray(f.waypoints[-1], float))
    traces += _vertiports(ports, go)
    operated = folder.operated
    rejected = _rejected_flights(folder.path, {f.id for f in flights})
    if operated:
        t0 = min(o.departure_s for o in operated)
        t1 = max(o.arrival_s for o in operated)
    else:
        t0 = t1 = 0.0
    step = float(step_s) if step_s is not None else DEFAULT_STEP_S
    step = max(step, (t1 - t0) / (MAX_FRAMES - 1)) if t1 > t0 else step
    times = np.arange(math.floor(t0 / step) * step, t1 + step, step) if operated else np.array([0.0])
    pos = np.zeros((len(operated), len(times), 3))
    live = np.zeros((len(operated), len(times)), dtype=bool)
    for n, o in enumerate(operated):
        pos[n], live[n] = _flight_positions(o, times)
    delay = np.array([o.departure_s - o.flight.planned_departure_s for o in operated])
    max_delay = float(delay.max()) if len(delay) and delay.max() > 0 else 1.0
    label = [f"{o.flight.id}" for o in operated]

    route_index = {r: i for i, r in enumerate(routes)}
    category = np.array([len(routes) if label[i] in rejected else route_index[o.flight.route]
                         for i, o in enumerate(operated)], dtype=np.uint16)
    hover = [[html.escape(label[i]), html.escape(o.flight.aircraft), html.escape(o.flight.route), f"{delay[i]:.1f}"]
             for i, o in enumerate(operated)]  # the same for a flight at every frame; its altitude from z
    template = ("flight %{customdata[0]}<br>aircraft %{customdata[1]}<br>route %{customdata[2]}<br>"
                "delay %{customdata[3]} s<br>z %{z:.0f} m<extra></extra>")
    big = np.array([label[i] in rejected for i in range(len(operated))], dtype=bool)

    def aircraft_traces(k: int) -> list[dict]:
        """The airborne aircraft at frame k, twice (coloured by route, by delay): only what changes
        from frame to frame (positions, who is airborne); colour scales and the template in the
        first frame's traces. Positions in float32 (a millimetre at 20 km)."""
        on = np.flatnonzero(live[:, k])
        xyz = {c: _typed(pos[on, k, n], "f4") for n, c in enumerate("xyz")}
        custom = [hover[i] for i in on]
        size = _typed(np.where(big[on], AIRCRAFT_SIZE + 5, AIRCRAFT_SIZE), "u1") if big.any() else AIRCRAFT_SIZE
        return [{"type": "scatter3d", **xyz, "customdata": custom, "marker": {"color": _typed(category[on], "u2"),
                                                                             "size": size}},
                {"type": "scatter3d", **xyz, "customdata": custom, "marker": {"color": _typed(delay[on], "f4"),
                                                                             "size": size}}]

    first = len(traces)
    n_cat = len(routes) + 1  # the routes' colours, then the conflict colour
    steps = [[edge / n_cat, c] for k, c in enumerate([colour[r] for r in routes] + [CONFLICT_COLOUR])
             for edge in (k, k + 1)]
    by_route, by_delay = aircraft_traces(0)
    by_route.update(name="aircraft (colour: route)", mode="markers", hovertemplate=template)
    by_route["marker"].update(colorscale=steps, cmin=-0.5, cmax=n_cat - 0.5, showscale=False,
                              line={"color": "#000000", "width": 2})
    by_delay.update(name="aircraft (colour: delay)", mode="markers", hovertemplate=template, visible=False)
    by_delay["marker"].update(colorscale="Viridis", cmin=0.0, cmax=max_delay, showscale=True,
                              line={"color": "#ffffff", "width": 1},
                              colorbar={"title": {"text": "delay (s)"}, "x": 1.02, "len": 0.5})
    data = [*_plain(traces), by_route, by_delay]
    clock = [f"{int(t // 3600):02d}:{int(t % 3600 // 60):02d}:{int(t % 60):02d}" for t in times]
    frames = [{"name": clock[k], "data": aircraft_traces(k), "traces": [first, first + 1]} for k in range(len(times))]
    cancelled = [f.id for f in flights if f.id not in {o.flight.id for o in operated}]
    title = f"uamopt schedule {folder.path.name}: {len(operated)} operated, {len(cancelled)} cancelled"
    if rejected:
        title += f"; verifier rejects {len(rejected)} flights (red)"
    shown = ", ".join(cancelled[:30]) + (f" … (+{len(cancelled) - 30})" if len(cancelled) > 30 else "")
    n_traces = len(data)
    vis_route = [True] * n_traces
    vis_delay = [True] * n_traces
    vis_route[first + 1] = False
    vis_delay[first] = False
    for n, tr in enumerate(data[:first]):  # keep what the legend has hidden hidden
        if tr.get("visible") == "legendonly":
            vis_route[n] = vis_delay[n] = "legendonly"
    play = [{"label": f"▶ {name}", "method": "animate",
             "args": [None, {"frame": {"duration": ms, "redraw": True}, "fromcurrent": True, "transition": {"duration": 0},
                             "mode": "immediate"}]} for name, ms in SPEEDS.items()]
    pause = {"label": "❚❚", "method": "animate",
             "args": [[None], {"frame": {"duration": 0, "redraw": False}, "mode": "immediate", "transition": {"duration": 0}}]}
    layout = {
        "title": {"text": html.escape(title) + (f"<br><sup>cancelled: {html.escape(shown)}</sup>" if cancelled else ""),
                  "x": 0.01},
        "scene": SCENE,
        "legend": {"itemsizing": "constant", "x": 1.0, "xanchor": "left", "y": 1.0},
        "margin": {"l": 0, "r": 230, "t": 70, "b": 130}, "height": 820, "width": 1280, "uirevision": "keep",
        "updatemenus": [
            {"type": "buttons", "direction": "left", "x": 0.0, "y": 0.0, "xanchor": "left", "yanchor": "top",
             "buttons": [*play, pause], "showactive": False, "pad": {"t": 75}},
            {"type": "dropdown", "x": 0.32, "y": 0.0, "xanchor": "left", "yanchor": "top", "pad": {"t": 75},
             "buttons": [{"label": "colour: route", "method": "restyle", "args": [{"visible": vis_route}]},
                         {"label": "colour: delay", "method": "restyle", "args": [{"visible": vis_delay}]}]}],
        "sliders": [{"active": 0, "x": 0.0, "y": 0.0, "yanchor": "top", "len": 1.0, "pad": {"t": 5},
                     "currentvalue": {"prefix": "clock "},
                     "steps": [{"label": clock[k], "method": "animate",
                                "args": [[clock[k]], {"frame": {"duration": 0, "redraw": True}, "mode": "immediate",
                                                      "transition": {"duration": 0}}]} for k in range(len(times))]}],
        "meta": {"uamopt": {"times_s": times.tolist(), "flights": label, "step_s": step,
                            "cancelled": cancelled, "rejected": sorted(rejected)}}}
    return Explorer(spec={"data": data, "layout": layout, "frames": frames}, title=title)
