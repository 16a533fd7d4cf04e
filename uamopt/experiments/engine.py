"""Running a sweep on Dask: ``uamopt sweep SWEEP.toml --out DIR`` and :func:`sweep`.

Each case that still lacks rows is one Dask task (:func:`uamopt.experiments.case.run_case`). By
default the tasks run on a ``LocalCluster`` on the loopback interface (processes, one thread
each, ``workers`` of them: the CPU count, at most one per case); with ``scheduler`` they run on
an existing cluster (``dask scheduler`` + ``dask worker`` processes with uamopt installed). The
client (this process) writes each case's rows as a part of the results folder the moment the
case finishes (store.py), so a kill loses only the cases still running, and a re-run computes
only what is missing. The final table is sorted by grid order, solver order and seed order, so
an interrupted and resumed sweep gives the same table as an uninterrupted one (its timing
column ``seconds`` aside).

Note: the local cluster starts worker processes with ``spawn``; a Python *script* calling
:func:`sweep` must do so under ``if __name__ == "__main__":`` (notebooks need nothing).
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from pathlib import Path

from uamopt.checks import expect, expect_path
from uamopt.cluster import connect, quiet_resource_tracker  # noqa: F401 (the sweeps' cluster, shared with the windows solver)
from uamopt.errors import UamoptError
from uamopt.experiments.case import error_line, run_case
from uamopt.experiments.spec import SweepSpec, load_sweep, toml_value
from uamopt.experiments.store import (
    ResultsFolder,
    columns,
    row_key,
    typed_frame,
    version,
)
from uamopt.optional import require
from uamopt.progress import Progress


def _swept_column(values: list):
    """The swept values as a column: numbers, booleans or strings as they are, anything else
    (lists, mixed types) as its TOML text."""
    import pandas as pd

    kinds = {bool if isinstance(v, bool) else (float if isinstance(v, (int, float)) else type(v)) for v in values}
    if kinds == {float}:
        ints = all(isinstance(v, int) for v in values)
        return pd.array(values, dtype="Int64" if ints else "float64")
    if kinds == {bool}:
        return pd.array(values, dtype="boolean")
    if kinds == {str}:
        return pd.array(values, dtype="string")
    return pd.array([toml_value(v) for v in values], dtype="string")


def results_table(spec: SweepSpec, frames: list):
    """Every row of ``spec`` found in ``frames``, with the swept columns, in table order."""
    import pandas as pd

    cols = columns(spec.stage)
    order = {key: i for i, key in enumerate(spec.row_keys())}
    cols = {"case": "str"} | cols
    frames = [typed_frame(f.to_dict("records"), cols) for f in frames if f is not None and len(f)]
    table = pd.concat(frames, ignore_index=True) if frames else typed_frame([], cols)
    position = [order.get(row_key(c, s, d), -1) for c, s, d in zip(table["case"], table["solver"], table["seed"], strict=True)]
    table = table.assign(_pos=position)
    table = table[table["_pos"] >= 0].drop_duplicates("_pos", keep="first").sort_values("_pos", kind="stable")
    by_id = {c.id: c for c in spec.cases}
    swept = {key: _swept_column([by_id[c].values[key] for c in table["case"]]) for key in spec.grid}
    table = table.drop(columns="_pos").reset_index(drop=True)
    for i, (key, column) in enumerate(swept.items()):
        table.insert(1 + i, key, column)
    return table


def _todo(spec: SweepSpec, done) -> tuple[list, set]:
    """(case, solvers, seeds) of every case lacking a row; a case lacking some rows runs the
    product of its missing solvers and seeds (the rows it already has are dropped afterwards)."""
    have = set() if done is None else {row_key(c, s, d)
                                       for c, s, d in zip(done["case"], done["solver"], done["seed"], strict=True)}
    todo = []
    for case in spec.cases:
        if spec.stage != "schedule":
            if (case.id, None, None) not in have:
                todo.append((case, (), ()))
            continue
        missing = [(p, s) for p in spec.solvers for s in spec.seeds if (case.id, p.name, s) not in have]
        if missing:
            solvers = tuple(p for p in spec.solvers if any(m[0] is p for m in missing))
            seeds = tuple(s for s in spec.seeds if any(m[1] == s for m in missing))
            todo.append((case, solvers, seeds))
    return todo, have


def _rows(case, rows: list[dict], have: set, stage: str):
    cols = columns(stage)
    rows = [{**r, "case": case.id, "uamopt_version": version()} for r in rows]
    rows = [r for r in rows if row_key(r["case"], r.get("solver"), r.get("seed")) not in have]
    return typed_frame(rows, {"case": "str"} | cols)


def _run(spec: SweepSpec, folder: ResultsFolder, todo: list, have: set, client, progress: Progress) -> tuple[list, int]:
    """Submit the cases, save each as it finishes; returns the frames not saved (lost to the cluster)."""
    from distributed import as_completed

    futures = {}
    for case, solvers, seeds in todo:
        future = client.submit(run_case, case.scenario, spec.stage, solvers, seeds, pure=False,
                               key=f"uamopt-case-{case.id}-{os.urandom(4).hex()}")
        futures[future] = (case, solvers, seeds)
    unsaved, failed = [], 0
    for future in as_completed(futures):
        case, solvers, seeds = futures.pop(future)
        try:
            frame = _rows(case, future.result(), have, spec.stage)
            folder.write_part(case.id, frame, remaining=len(futures))  # a full disk: UamoptError, the parts saved kept
        except UamoptError:
            raise
        except Exception as exc:  # noqa: BLE001 - the cluster lost the task: report it, do not save it
            keys = [{"solver": p.name, "seed": s} for p in solvers for s in seeds] or [{}]
            frame = _rows(case, [{**k, "status": "error", "error": f"not saved, re-run to retry: {error_line(exc)}"}
                                 for k in keys], have, spec.stage)
            unsaved.append(frame)
        failed += int((frame["status"] == "error").any())
        progress.update(1, f"{failed} with errors" if failed else "")
    return unsaved, failed


def sweep(path, out=None, scheduler: str | None = None, workers: int | None = None, small: bool = False):
    """Run a sweep file and return the rows of its ``results.parquet`` (a pandas DataFrame).

    Parameters
    ----------
    path : str or Path
        The sweep TOML file (format: uamopt/experiments/spec.py, docs/sweeps.md).
    out : str or Path, optional
        Results folder; re-running into it computes only the missing rows. Default: a temporary
        folder, removed afterwards.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); default a local cluster.
    workers : int, optional
        Worker processes of the local cluster (default: CPU count, at most one per case).
    small : bool
        Apply the file's ``[small]`` table.

    Raises
    ------
    UamoptError
        Bad sweep file, unreachable scheduler, a results folder that is not this sweep's or is
        corrupt; raised before anything runs or is written. A full disk or file-size limit
        during a write (the cases saved before it are kept; a re-run computes the rest).

    Warns
    -----
    SetAsideWarning
        A part of the results folder broke the schema (uamopt/experiments/store.py) and was
        renamed ``NAME.parquet.set-aside``; its case is recomputed.
    """
    expect_path(path, "path", "sweep")
    expect(small, bool, "small", "sweep")

    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise UamoptError(f"--workers must be a whole number ≥ 1, got {workers!r}", "--workers",
                          "give a number of worker processes")
    if workers is not None and scheduler:
        raise UamoptError("--workers applies to the local cluster, not to --scheduler", "--workers",
                          "drop --workers (the cluster's workers are started with `dask worker`)")
    from uamopt.outputs import output_lock

    require("distributed", "pyarrow", extra="sweep", what="a sweep (Dask, results.parquet)")
    spec = load_sweep(path, small=small)
    if out is not None:
        with output_lock(out):  # one sweep at a time into a results folder
            return _sweep(spec, ResultsFolder(out), scheduler, workers)
    folder = ResultsFolder(tempfile.mkdtemp(prefix="uamopt-sweep-"))
    try:
        return _sweep(spec, folder, scheduler, workers)
    finally:
        shutil.rmtree(folder.out, ignore_errors=True)


def _sweep(spec: SweepSpec, folder: ResultsFolder, scheduler, workers):
    done, broken = folder.check(spec)
    todo, have = _todo(spec, done)
    unsaved, stats = [], {"cases": len(spec.cases), "run": len(todo), "errors": 0, "set_aside": []}
    if todo:
        scratch = tempfile.mkdtemp(prefix="uamopt-dask-")  # the workers' scratch space, removed afterwards
        try:
            client, cluster = connect(scheduler, workers, len(todo), scratch)
            from uamopt.solvers.watchdog import warm_workers

            warm_workers(client)  # the cases' exact solves start without waiting for their imports
            try:
                stats["set_aside"] = folder.start(spec, broken)
                with Progress(len(todo), f"sweep {spec.name}", "cases") as progress:
                    unsaved, stats["errors"] = _run(spec, folder, todo, have, client, progress)
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
    else:
        stats["set_aside"] = folder.start(spec, broken)
    table = results_table(spec, [folder.read_parts(spec.stage)[0], *unsaved])
    folder.write_results(table)
    if spec.figure:
        from uamopt.plotting.sweeps import save_sweep_figure

        save_sweep_figure(table, spec, folder.out / "figure.png")
    table.attrs.update(stats | {"unsaved": len(unsaved), "out": str(folder.out)})
    return table


def cmd_sweep(args) -> int:
    """``uamopt sweep``: run, then one summary line on stdout."""
    from uamopt.interrupts import describe, handled
    from uamopt.outputs import check_out_dir

    default = Path("out") / "sweeps" / (Path(args.sweep).stem + ("-small" if args.small else ""))
    out = default if args.out is None else check_out_dir(args.out)
    try:
        table = sweep(args.sweep, out=out, scheduler=args.scheduler, workers=args.workers, small=args.small)
    except KeyboardInterrupt as exc:
        sys.stderr.write(f"{describe(exc)}: finished cases are saved in {out}: re-run the same command to finish\n")
        return handled(exc)
    a = table.attrs
    errors = int((table["status"] == "error").sum())
    print(f"sweep {out}: {len(table)} rows ({errors} with errors), {a['run']} of {a['cases']} cases run now, "
          f"{a['cases'] - a['run']} already done -> {out / 'results.parquet'}")
    if a["unsaved"]:
        sys.stderr.write(f"error: {a['unsaved']} cases were lost by the cluster and not saved ({out}): re-run to retry\n")
        return 1
    return 0
