"""The package as users get it (issue 21): the wheel and the sdist hold the shipped scenarios and
solver profiles, an installed wheel reads its own copies from any folder, and the core installs
and runs alone, a command of a missing extra saying which extra in one line (exit 2).

The layout (pyproject.toml): the files live in ``uamopt/models/`` and ``uamopt/solvers/profiles/``
and the checkout's ``models/`` and ``solvers/`` are links to them. The build tests (``-m slow``,
about a minute and a half) build the sdist and, from it, the wheel with ``python -m build`` in a
venv of their own (setuptools >= 77, wheel and build from the package registry: .venv's
setuptools is older than pyproject's build-system asks), then install the wheel ``--no-deps``
into fresh venvs outside the checkout whose dependencies are .venv's own files, linked by a .pth
file (no download): all of .venv for the full install, only the core's dependency closure for
the core alone.
"""

from __future__ import annotations

import fnmatch
import json
import os
import subprocess
import sys
import sysconfig
import tarfile
import time
import tomllib
import zipfile
from importlib import metadata
from pathlib import Path

import pytest
from conftest import ROOT

PACKAGE = ROOT / "uamopt"
SHIPPED = {"models": PACKAGE / "models", "solvers": PACKAGE / "solvers" / "profiles"}
SITE = Path(sysconfig.get_paths()["purelib"])  # .venv's site-packages (purelib = platlib here)
TINY = ["--set", "grid.cell=[50,50,30]"]


def shipped_files() -> list[str]:
    """Every shipped data file, relative to the package folder (``models/paper_case.toml``, ...)."""
    return sorted(str(p.relative_to(PACKAGE)) for folder in SHIPPED.values() for p in folder.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


def test_the_top_level_folders_link_into_the_package():
    for name, folder in SHIPPED.items():
        assert (ROOT / name).is_symlink(), f"{name}/ should be a link to {folder.relative_to(ROOT)}"
        assert (ROOT / name).resolve() == folder.resolve()
    assert (ROOT / "models" / "paper_case.toml").is_file() and (ROOT / "solvers" / "rolling.toml").is_file()


def test_every_shipped_file_is_package_data():
    """Each file under the two folders matches a [tool.setuptools.package-data] pattern (or is a
    module, make_dsm_example.py): a new kind of file (a .pbf, a .csv) must be added there."""
    patterns = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    missing = []
    for name in shipped_files():
        folder, _, base = ("uamopt/" + name).rpartition("/")
        if base.endswith(".py"):
            continue
        if not any(fnmatch.fnmatch(base, p) for p in patterns.get(folder.replace("/", "."), [])):
            missing.append(name)
    assert not missing, f"not package data in pyproject.toml: {missing}"


def test_the_profile_lookup_reads_the_package():
    from uamopt.shipped import models_dir, profiles_dir
    from uamopt.solvers import PROFILE_DIR

    assert PROFILE_DIR == profiles_dir() == SHIPPED["solvers"]
    assert models_dir() == SHIPPED["models"]


# --- built and installed ---------------------------------------------------------------------------


def run(args, cwd: Path, timeout: float = 600, check: bool = True) -> subprocess.CompletedProcess:
    """A command in a clean environment: no PYTHONPATH, no active venv, the figures' backend Agg."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["MPLBACKEND"] = "Agg"
    done = subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout,
                          check=False)
    if check and done.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, args))} -> {done.returncode}\n{done.stdout}\n{done.stderr}")
    return done


def venv(path: Path, links: list[Path]) -> Path:
    """A fresh venv (no system site-packages) whose sys.path ends with ``links`` (a .pth file of
    plain paths: their own .pth files, .venv's editable install among them, are not read)."""
    run([sys.executable, "-m", "venv", path], cwd=path.parent)
    python = path / "bin" / "python"
    site = Path(run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=path).stdout.strip())
    (site / "uamopt_test_links.pth").write_text("".join(f"{p}\n" for p in links))
    return python


@pytest.fixture(scope="module")
def dist(tmp_path_factory) -> dict:
    """The sdist and the wheel built from it, and how long each step took."""
    tmp = tmp_path_factory.mktemp("build")
    seconds = {}
    t0 = time.perf_counter()
    run([sys.executable, "-m", "venv", tmp / "tools"], cwd=tmp)
    tools = tmp / "tools" / "bin" / "python"
    got = run([tools, "-m", "pip", "install", "--quiet", "setuptools>=77", "wheel", "build"], cwd=tmp, check=False)
    if got.returncode != 0:
        reason = f"the build tools could not be installed from the package registry: {got.stderr.strip()[-300:]}"
        if os.environ.get("CI"):  # CI reaches the registry: there a failed install is a failure, not a skip
            pytest.fail(reason)
        pytest.skip(reason)  # a contributor offline: the wheel cannot be built without setuptools >= 77
    seconds["build tools"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    run([tools, "-m", "build", "--no-isolation", "--outdir", tmp / "dist", ROOT], cwd=tmp)
    seconds["sdist and wheel"] = time.perf_counter() - t0
    (wheel,) = (tmp / "dist").glob("uamopt-*.whl")
    (sdist,) = (tmp / "dist").glob("uamopt-*.tar.gz")
    return {"wheel": wheel, "sdist": sdist, "seconds": seconds}


@pytest.mark.slow
def test_the_wheel_and_the_sdist_hold_every_shipped_file(dist):
    import uamopt

    expected = shipped_files()
    assert {"models/paper_case.toml", "models/variants/speed.toml", "models/data/dsm_example.tif",
            "solvers/profiles/rolling.toml", "solvers/profiles/exact.toml"} <= set(expected)
    with zipfile.ZipFile(dist["wheel"]) as whl:
        names = set(whl.namelist())
        meta = whl.read(f"uamopt-{uamopt.__version__}.dist-info/METADATA").decode()
    assert {f"uamopt/{n}" for n in expected} <= names, sorted({f"uamopt/{n}" for n in expected} - names)
    assert f"\nVersion: {uamopt.__version__}\n" in meta  # the one version, from uamopt/__init__.py
    with tarfile.open(dist["sdist"]) as sd:
        members = {m.name.split("/", 1)[1]: m for m in sd.getmembers() if "/" in m.name}
    for name in expected:
        member = members.get(f"uamopt/{name}")
        assert member is not None and member.isfile(), f"uamopt/{name} is not a file in the sdist"
    assert not [n for n, m in members.items() if m.issym() or m.islnk()]


@pytest.mark.slow
def test_an_installed_wheel_reads_its_own_scenarios_and_profiles(dist, tmp_path):
    """The wheel installed --no-deps into a fresh venv, its dependencies .venv's (a .pth file), run
    from a folder outside the checkout: shipped names and the documented models/..., solvers/...
    paths find the package's files."""
    t0 = time.perf_counter()
    python = venv(tmp_path / "venv", [SITE])
    run([python, "-m", "pip", "install", "--quiet", "--no-deps", dist["wheel"]], cwd=tmp_path)
    installed = time.perf_counter() - t0
    work = tmp_path / "work"
    work.mkdir()
    uamopt_cmd = tmp_path / "venv" / "bin" / "uamopt"

    code = """if True:
        import json, tomllib, uamopt
        from uamopt.shipped import models_dir, profiles_dir
        from uamopt.solvers import PROFILE_DIR, load_profile
        rolling, exact = load_profile("rolling"), load_profile("exact")
        print(json.dumps({"package": uamopt.__file__, "models": str(models_dir()), "profiles": str(PROFILE_DIR),
                          "rolling": [rolling.solver, rolling.time_limit_s, rolling.options],
                          "exact": [exact.solver, exact.time_limit_s, exact.options],
                          "by_path": load_profile("solvers/rolling.toml") == rolling,
                          "rolling_file": tomllib.loads((profiles_dir() / "rolling.toml").read_text())}))
    """
    got = json.loads(run([python, "-c", code], cwd=work).stdout)
    venv_root = str(tmp_path / "venv")
    for key in ("package", "models", "profiles"):
        assert got[key].startswith(venv_root) and not got[key].startswith(str(ROOT)), (key, got[key])
    assert got["rolling"] == ["rolling", 480.0, {"window_s": 900.0, "inner": "cpsat"}]
    assert got["rolling"][1] == got["rolling_file"]["time_limit_s"]
    assert got["exact"][:2] == ["timeindexed", 300.0] and got["exact"][2]["step_s"] == 10.0
    assert got["by_path"]

    t0 = time.perf_counter()
    for name in ("paper_case", "models/paper_case.toml"):  # a shipped name; the documented path, not here
        out = work / name.replace("/", "_")
        done = run([uamopt_cmd, "risk", name, *TINY, "--no-figures", "--out", out], cwd=work)
        assert "risk field: 54,000 cells" in done.stdout and (out / "risk.npz").is_file()
    run([uamopt_cmd, "risk", "dsm_example", "--set", "grid.cell=[50,50,30]", "--no-figures", "--out", work / "dsm"],
        cwd=work)  # the scenario's GeoTIFF and GeoJSON, package data beside it
    sched = work / "sched"
    done = run([uamopt_cmd, "schedule", "paper_case", *TINY, "--solver", "solvers/greedy.toml", "--out", sched], cwd=work)
    assert done.stdout.startswith("greedy: ")
    recorded = json.loads((sched / "summary.json").read_text())["scenario"]["file"]
    assert recorded.startswith(venv_root) and recorded.endswith("uamopt/models/paper_case.toml")
    assert run([uamopt_cmd, "verify", sched], cwd=work).returncode == 0
    print(f"\nwheel install {installed:.1f} s, commands {time.perf_counter() - t0:.1f} s; build {dist['seconds']}")


def core_closure() -> set[str]:
    """The distributions of the core dependencies ([project].dependencies) and of theirs, as
    installed in .venv (markers evaluated, requested extras followed)."""
    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name

    core = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    seen: dict[str, set] = {}
    todo = [(Requirement(r), "") for r in core]
    while todo:
        req, extra = todo.pop()
        if req.marker is not None and not req.marker.evaluate({"extra": extra}):
            continue
        name = canonicalize_name(req.name)
        extras = set(req.extras)
        if name in seen and extras <= seen[name]:
            continue
        seen[name] = seen.get(name, set()) | extras
        for text in metadata.distribution(name).requires or []:
            sub = Requirement(text)
            todo += [(sub, e) for e in sorted(seen[name]) or [""]]
    return set(seen)


def link_farm(folder: Path, names: set[str]) -> int:
    """Links in ``folder`` to the files of .venv's distributions ``names`` only: a top-level entry
    (a package, its .libs, its dist-info) that no other distribution shares is linked whole, a
    shared one (``__pycache__``, a namespace package) file by file. Returns the links made."""
    from packaging.utils import canonicalize_name

    owners: dict[str, set[str]] = {}
    files: dict[str, list] = {}
    for dist in metadata.distributions(path=[str(SITE)]):
        name = canonicalize_name(dist.metadata["Name"])
        files[name] = [f for f in dist.files or [] if f.parts and f.parts[0] != ".."]
        for f in files[name]:
            owners.setdefault(f.parts[0], set()).add(name)
    made = 0
    for name in sorted(names):
        assert files.get(name), f"{name}: no RECORD in .venv, its files cannot be linked"
        for f in files[name]:
            top = f.parts[0]
            whole = owners[top] <= names and top != "__pycache__"
            target = folder / (top if whole else Path(*f.parts))
            if target.exists() or target.is_symlink() or not (SITE / target.relative_to(folder)).exists():
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(SITE / target.relative_to(folder))
            made += 1
    return made


@pytest.mark.slow
def test_the_core_installs_and_runs_alone(dist, tmp_path):
    """The wheel with only its core dependencies (.venv's files of the core's dependency closure,
    linked; no extra's package present): the pipeline runs from ``import uamopt``, and a command
    that needs an extra says which in one line, exit code 2."""
    t0 = time.perf_counter()
    closure = core_closure()
    assert {"numpy", "scipy", "cvxpy", "rasterio", "numba"} <= closure
    assert not closure & {"pyomo", "ortools", "pyrosm", "dask", "distributed", "pyarrow", "plotly", "bluesky-simulator"}
    farm = tmp_path / "core-site"
    farm.mkdir()
    links = link_farm(farm, closure)
    python = venv(tmp_path / "venv", [farm])
    run([python, "-m", "pip", "install", "--quiet", "--no-deps", dist["wheel"]], cwd=tmp_path)
    check = run([python, "-m", "pip", "check"], cwd=tmp_path, check=False)
    assert check.returncode == 0, f"the core's dependencies are incomplete: {check.stdout}"
    installed = time.perf_counter() - t0
    work = tmp_path / "work"
    work.mkdir()
    uamopt_cmd = tmp_path / "venv" / "bin" / "uamopt"

    t0 = time.perf_counter()
    code = """if True:
        import importlib.util, sys
        import uamopt as ua
        from uamopt.shipped import models_dir
        absent = [m for m in ("pyomo", "ortools", "pyrosm", "dask", "distributed", "pyarrow", "plotly", "bluesky")
                  if importlib.util.find_spec(m) is not None]
        assert not absent, absent
        scenario = ua.load_scenario(models_dir() / "paper_case.toml", ["grid.cell=[50,50,30]"])
        field = ua.compute_risk(scenario)
        model = ua.planning_model(scenario, field)
        plan = ua.plan_track(model, "V1", "V4")
        problem = ua.build_problem(ua.generate_flights(scenario, ua.plan_network(model)), scenario)
        schedule = ua.solve(problem, "greedy")
        assert ua.verify(problem, schedule).ok
        print(ua.__file__, field.summary()["cells"], round(plan.stages["optimal"].length_m), schedule.solver)
    """
    package, cells, _, solver = run([python, "-c", code], cwd=work).stdout.split()
    assert package.startswith(str(tmp_path / "venv")) and (cells, solver) == ("54000", "greedy")

    run([uamopt_cmd, "risk", "paper_case", *TINY, "--out", work / "risk"], cwd=work)  # figures included
    expected = {
        ("schedule", "paper_case", *TINY, "--solver", "highs", "--out", work / "s1"):
            "error: pyomo is not installed: the highs solver needs the [exact] extra; pip install 'uamopt[exact]'",
        ("schedule", "paper_case", *TINY, "--solver", "cpsat", "--out", work / "s2"):
            "error: ortools is not installed: the cpsat solver needs the [exact] extra; pip install 'uamopt[exact]'",
        ("schedule", "paper_case", *TINY, "--solver", "exact", "--out", work / "s3"):  # solvers/exact.toml
            "error: ortools is not installed: the timeindexed solver needs the [exact] extra; pip install 'uamopt[exact]'",
        ("bench", "paper_case", "--solver", "greedy", "highs", *TINY, "--out", work / "b"):
            "error: pyomo is not installed: the highs solver needs the [exact] extra; pip install 'uamopt[exact]'",
        ("risk", "helsinki", "--out", work / "h"):
            "error: pyrosm is not installed: reading OpenStreetMap needs the [osm] extra; pip install 'uamopt[osm]'",
        ("sweep", "variants/speed", "--small", "--out", work / "sw"):
            "error: distributed is not installed: a sweep (Dask, results.parquet) needs the [sweep] extra; "
            "pip install 'uamopt[sweep]'",
        ("view", work / "risk", "--out", work / "view.html"):
            "error: plotly is not installed: the 3-D view (uamopt view, explore) needs the [view] extra; "
            "pip install 'uamopt[view]'",
        ("reproduce", "paper_case", "--out", work / "rep"):
            "error: pyomo is not installed: uamopt reproduce (Table 3 runs highs and cpsat) needs the [exact] extra; "
            "pip install 'uamopt[exact]'",
    }
    for args, line in expected.items():
        done = run([uamopt_cmd, *args], cwd=work, check=False)
        assert (done.returncode, done.stderr.strip().splitlines()) == (2, [line]), (args, done.stderr)
        assert not Path(args[-1]).exists(), args  # refused before anything was written
    print(f"\ncore: {len(closure)} distributions, {links} links, venv and wheel {installed:.1f} s, "
          f"commands {time.perf_counter() - t0:.1f} s")
