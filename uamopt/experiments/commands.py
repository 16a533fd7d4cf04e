"""The ``sweep`` subcommand's arguments, registered on the CLI without importing the engine
(Dask, numpy, pandas load only when a sweep runs: ``uamopt --help`` stays fast)."""

from __future__ import annotations


def _cmd_sweep(args) -> int:
    from uamopt.experiments.engine import cmd_sweep

    return cmd_sweep(args)


def add_sweep_command(sub) -> None:
    """Register ``uamopt sweep`` on the CLI's subparsers (cli.py calls this)."""
    p = sub.add_parser("sweep", help="run a sweep file's cases on Dask: results.parquet (resumable)",
                       description="run a sweep file's cases on Dask: results.parquet (resumable); see docs/sweeps.md")
    p.add_argument("sweep", help="sweep TOML file, e.g. models/variants/speed.toml")
    p.add_argument("--out", help="results folder (default: out/sweeps/NAME); re-running into it computes only missing rows")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="a running Dask scheduler, e.g. tcp://127.0.0.1:8786 (default: a local cluster)")
    p.add_argument("--workers", type=int, metavar="N", help="worker processes of the local cluster (default: CPU count)")
    p.add_argument("--small", action="store_true", help="apply the file's [small] table (a fast version)")
    p.set_defaults(func=_cmd_sweep)
