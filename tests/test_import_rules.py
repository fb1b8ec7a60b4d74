"""The solver core must not import CAD, meshing or rendering libraries (design rule)."""

import subprocess
import sys

import pytest

HEAVY = ("build123d", "OCP", "gmsh", "pyvista", "vtk", "matplotlib")

CORE = ["tactileskin.scene", "tactileskin.geometry.fingertip", "tactileskin.sweep",
        "tactileskin.discrimination"]
LATER = ["tactileskin.materials", "tactileskin.fe", "tactileskin.results",
         "tactileskin.geometry.indenters", "tactileskin.geometry.braille"]


def _imports(module):
    code = (f"import sys, {module}; print(','.join(m for m in {HEAVY!r} if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip()


@pytest.mark.parametrize("module", CORE + LATER)
def test_core_stays_light(module):
    assert _imports(module) == ""


def test_only_the_file_indenter_uses_trimesh():
    """geometry/indenters/ is pure numpy/scipy, except file.py: a user's STL must be read and
    its triangles' closest points computed by a maintained library (trimesh), imported inside
    its functions. Importing the package must not load trimesh, and no other kind names it."""
    from pathlib import Path

    import tactileskin.geometry.indenters as pkg

    code = "import sys, tactileskin.geometry.indenters; print('trimesh' in sys.modules)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "False"
    users = sorted(p.name for p in Path(pkg.__path__[0]).glob("*.py") if "trimesh" in p.read_text())
    assert users == ["file.py"]


def test_scenes_and_the_cli_import_no_scipy_optimize():
    """The sweep's main process imported scipy.optimize (~0.3 s idle, 0.7 s loaded) with the
    fingertip geometry for brentq, which only the solving workers call: imported where used."""
    code = ("import sys; import tactileskin.cli.sweep; from tactileskin.scene import Scene; "
            "from tactileskin.sweep import case_ids, expand_grid; "
            "assert len(case_ids(expand_grid(base=Scene(), quality='preview'))) == 18; "
            "print('scipy.optimize' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "False"


@pytest.mark.slow
def test_the_main_job_runs_without_pyvista(tmp_path):
    """pyvista/VTK (566 MB) is the optional `render` extra: a sweep with its report, figures
    and Fig. 9 render (matplotlib) runs with `import pyvista` and `import vtk` failing, and
    Result.to_pyvista() then names the extra to install."""
    out = tmp_path / "o"
    code = (
        "import sys\n"
        "for m in ('pyvista', 'vtk', 'vtkmodules'): sys.modules[m] = None\n"
        "from tactileskin.cli import main\n"
        f"rc = main(['sweep', '-t', '1', '-i', 'flat', '-m', 'polyurethane', '--quality', 'preview', "
        f"'--serial', '-o', {str(out)!r}])\n"
        "assert not any(m in sys.modules and sys.modules[m] is not None for m in ('pyvista', 'vtk'))\n"
        "sys.exit(rc)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert (out / "fig9_t1-polyurethane-flat-2d.png").is_file() and (out / "report.md").is_file()
    assert "WARNING" not in r.stderr and "render" not in r.stderr


def test_every_imported_library_is_a_declared_dependency():
    """`pip install tactileskin` installs pyproject's dependencies only: array.classify imported
    scikit-learn, which no requirement named (requirements.lock had it, so ./dev worked)."""
    import ast
    import re
    import tomllib
    from importlib.metadata import packages_distributions
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    mods = set()
    for p in (root / "src" / "tactileskin").rglob("*.py"):
        for n in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(n, ast.Import):
                mods |= {a.name.split(".")[0] for a in n.names}
            elif isinstance(n, ast.ImportFrom) and n.level == 0 and n.module:
                mods.add(n.module.split(".")[0])
    project = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    reqs = project["dependencies"] + [r for extra in project["optional-dependencies"].values() for r in extra]
    declared = {re.split(r"[<>=;\[ ]", r)[0].lower().replace("_", "-") for r in reqs}
    # installed by a declared one: build123d's OpenCascade, dask[distributed], pyvista's VTK
    via = {"OCP": "build123d", "distributed": "dask", "vtkmodules": "pyvista", "mpl_toolkits": "matplotlib"}
    dists = packages_distributions()
    missing = []
    for m in sorted(mods - set(sys.stdlib_module_names) - {"tactileskin"}):
        names = {d.lower().replace("_", "-") for d in dists.get(m, [m])} | {via.get(m, "")}
        if not names & declared:
            missing.append(m)
    assert missing == []


@pytest.mark.slow
def test_a_cached_sweep_writes_its_report_without_the_solver(tmp_path):
    """The report's run settings list SolverOptions' defaults: taken from tactileskin.fe.solver,
    they imported the solver (numba, scikit-fem; ~0.3 s idle, 0.8 s loaded) into every sweep's
    main process, which never solves. A cached rerun writes its tables, figures, render and
    report with none of them loaded, and the report still lists the solver's own defaults."""
    import dataclasses

    from tactileskin.cli import main
    from tactileskin.fe.solver import SolverOptions

    out = tmp_path / "o"
    args = ["sweep", "-t", "1", "-i", "flat", "-m", "polyurethane", "--quality", "preview", "--serial",
            "-o", str(out)]
    assert main(args) == 0
    code = ("import sys\nfrom tactileskin.cli import main\n"
            f"rc = main({args!r})\n"
            "print('loaded:', ','.join(m for m in ('tactileskin.fe', 'numba', 'skfem') if m in sys.modules))\n"
            "sys.exit(rc)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1] == "loaded: "
    report = (out / "report.md").read_text(encoding="utf-8")
    for f in dataclasses.fields(SolverOptions):
        assert f"{f.name} = {getattr(SolverOptions(), f.name)!r}" in report
