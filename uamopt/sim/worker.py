"""Run one BlueSky scenario headless in fast time and record the traffic (a subprocess of the replay).

``python -m uamopt.sim.worker SCN OUT.npz --workdir DIR --until SECONDS [--parent PID]``

BlueSky keeps global state, so :func:`uamopt.sim.replay.replay` runs each scenario in a fresh
process of this module. It initialises BlueSky without networking (``detached=True``, never
``--headless``, which starts a server), loads the scenario with ``IC`` (which resets the clock),
runs conflict detection at every clock step instead of once a second, and steps until every
aircraft has been created and deleted (or ``--until``). Recorded, after every step: the clock and
each aircraft's latitude, longitude and altitude; every change of BlueSky's own set of pairs in
loss of separation (``traf.cd.lospairs_unique``).

One patch: BlueSky 1.1.1's compiled ``kwikqdrdist_matrix`` returns symmetric bearings; the
Python version replaces it (the distances used for LoS are the same in both).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import time

import numpy as np


def run(scn: str, out: str, workdir: str, until_s: float) -> dict:
    import bluesky as bs

    with contextlib.redirect_stdout(sys.stderr):  # BlueSky prints its start-up log
        bs.init(mode="sim", detached=True, workdir=workdir)
    from bluesky.core import simtime
    from bluesky.tools import geo

    geo.kwikqdrdist_matrix = geo._geo.kwikqdrdist_matrix
    bs.stack.stack(f"IC {scn}")
    bs.sim.step()  # IC: reset, then the commands at t = 0 (DT, zone, ...)
    bs.sim.step()
    simtime.setdt(bs.sim.simdt, "asas")  # LoS checked at every step, not once a second
    from bluesky.traffic.asas import ConflictDetection

    acids: list[str] = []
    index: dict[str, int] = {}
    actypes: dict[str, str] = {}
    chunks: list[tuple] = []
    los_open: dict[frozenset, float] = {}
    los_events: list[list] = []
    started, started_cpu = time.perf_counter(), time.process_time()
    steps = 0
    while bs.sim.simt < until_s:
        bs.sim.step()
        steps += 1
        traf, t = bs.traf, float(bs.sim.simt)
        for n, acid in enumerate(traf.id):
            if acid not in index:
                index[acid] = len(acids)
                acids.append(acid)
                actypes[acid] = str(traf.perf.actype[n])  # an unknown type silently becomes B744
        if traf.ntraf:
            chunks.append((np.full(traf.ntraf, t), np.array([index[a] for a in traf.id], dtype=np.int32),
                           np.array(traf.lat), np.array(traf.lon), np.array(traf.alt)))
        # detection ran inside this step on the state before the move: that state's time is t − dt
        now = {p for p in traf.cd.lospairs_unique if len(p) == 2}
        t_state = t - float(bs.sim.simdt)
        for pair in now - los_open.keys():
            los_open[pair] = t_state
        for pair in set(los_open) - now:
            los_events.append([*sorted(pair), los_open.pop(pair), t_state])
        if traf.ntraf == 0 and not bs.stack.get_scendata()[0] and acids:
            break
    for pair, t0 in los_open.items():
        los_events.append([*sorted(pair), t0, float(bs.sim.simt)])
    cat = [np.concatenate(c) if chunks else np.empty(0) for c in zip(*chunks, strict=True)] if chunks else [np.empty(0)] * 5
    meta = {"acids": acids, "actypes": actypes, "los": los_events, "dt_s": float(bs.sim.simdt),
            "end_s": float(bs.sim.simt), "steps": steps, "wall_s": time.perf_counter() - started,
            "cpu_s": time.process_time() - started_cpu, "process_cpu_s": time.process_time(),
            "cd_method": ConflictDetection.selected().__name__,
            "zone_m": [float(traf.cd.rpz_def), float(traf.cd.hpz_def)], "bluesky": _version()}
    np.savez_compressed(out, t=cat[0], ac=cat[1].astype(np.int32), lat=cat[2], lon=cat[3], alt=cat[4],
                        meta=np.array(json.dumps(meta)))
    return meta


def follow_parent(parent: int) -> None:
    """End this worker when the replay that started it ends, even by SIGKILL (which runs no
    clean-up in the parent: the worker ran on alone). Linux: the kernel sends SIGKILL to us when the
    parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere, and as a check that the parent did not
    die before that call, a daemon thread watches the parent's pid every 0.2 s."""
    import os
    import threading

    with contextlib.suppress(Exception):  # not Linux, or no libc: the thread below does it
        import ctypes
        import signal

        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.2)
        os._exit(1)

    if os.getppid() != parent:
        os._exit(1)
    threading.Thread(target=watch, name="uamopt-parent-watch", daemon=True).start()


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("bluesky-simulator")
    except PackageNotFoundError:
        return "unknown"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m uamopt.sim.worker")
    parser.add_argument("scn")
    parser.add_argument("out")
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--until", type=float, required=True, help="stop at this clock time, s")
    parser.add_argument("--parent", type=int, help="the replay's pid: end when it ends")
    args = parser.parse_args(argv)
    if args.parent:
        follow_parent(args.parent)
    meta = run(args.scn, args.out, args.workdir, args.until)
    print(json.dumps({k: meta[k] for k in ("steps", "wall_s", "end_s")}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
