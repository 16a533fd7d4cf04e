"""Command line: ``uamopt COMMAND SCENARIO [--set KEY=VALUE ...] [--out DIR]`` (INTERFACES.md).

Bad input ends with one line ``error: <what> (<where>): <how to fix>`` on stderr and exit code 2;
results are staged and moved into ``--out`` only when complete.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from uamopt.errors import UamoptError

EXIT_BAD_INPUT = 2


class _Parser(argparse.ArgumentParser):
    """argparse with the project's one-line error and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"error: {message} (command line): see `{self.prog} --help`\n")
        raise SystemExit(EXIT_BAD_INPUT)


def _progress(total: int, desc: str):
    """A progress bar on a terminal, silent otherwise."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, disable=not sys.stderr.isatty(), leave=False)


def _load(args):
    from uamopt.scenario import load_scenario

    return load_scenario(args.scenario, args.set)


def _risk_stage(scenario, stage: Path, bar) -> dict:
    """Compute the risk field and write risk.npz, risk.png, summary.json into ``stage``."""
    from uamopt.outputs import write_json
    from uamopt.plots import plot_risk
    from uamopt.stages import compute_risk, risk_summary

    bar.set_description("risk field")
    run = compute_risk(scenario)
    bar.update(1)
    run.field.save_npz(stage / "risk.npz")
    bar.set_description("risk map")
    plot_risk(
        run.field, stage / "risk.png", vertiports=scenario.network.vertiports,
        cruise_altitude_m=scenario.network.cruise_altitude_m, title=scenario.name,
    )
    bar.update(1)
    summary = risk_summary(run)
    write_json(stage / "summary.json", summary)
    return summary


def cmd_risk(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output

    scenario = _load(args)
    check_out_dir(args.out)
    with _progress(2, "risk") as bar, staged_output(args.out) as stage:
        summary = _risk_stage(scenario, stage, bar)
    print(
        f"risk field: {summary['cells']:,} cells, {100 * summary['unsafe_share']:.1f} % unsafe, "
        f"{summary['seconds']['risk']:.2f} s -> {Path(args.out) / 'risk.npz'}"
    )
    return 0


def cmd_reproduce(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.report import risk_section, write_report

    scenario = _load(args)
    check_out_dir(args.out)
    with _progress(2, "reproduce") as bar, staged_output(args.out) as stage:
        summary = _risk_stage(scenario, stage, bar)
        write_report(stage / "report.md", scenario, [risk_section(scenario, summary)])
    print(f"report: {Path(args.out) / 'report.md'}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="uamopt", description="Urban Air Mobility risk fields, tracks and schedules.")
    parser.add_argument("--version", action="version", version="uamopt 0.1.0")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def command(name: str, func, help_text: str, default_out: str):
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.add_argument("scenario", help="scenario TOML file, e.g. models/paper_case.toml")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a scenario key (dotted, TOML value), e.g. grid.cell=[10,10,10]")
        p.add_argument("--out", default=default_out, help=f"output folder (default: {default_out})")
        p.set_defaults(func=func)
        return p

    command("risk", cmd_risk, "compute the operational risk field: risk.npz, risk.png, summary.json", "out/risk")
    command("reproduce", cmd_reproduce, "run every stage that applies and write report.md with figures", "out/reproduce")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except UamoptError as exc:
        sys.stderr.write(f"error: {exc.line()}\n")
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted (keyboard): nothing was written to --out\n")
        return 130


if __name__ == "__main__":
    sys.exit(main())
