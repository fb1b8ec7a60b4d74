"""The test session says so when the package's sources change while it runs: every test that
stores a solve in a cache then fails by design (cache.code_changes: 'restart Python'), and on a
loaded machine, where a run is long, an edit in the checkout under test made two such tests
read as flaky (test_one_entry_shared_by_equal_cases_is_solved_once, ['failed', 'failed'];
test_cli_sweep_lockup_in_results_csv_and_report, exit 1)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import tactileskin

CONFTEST = Path(__file__).with_name("conftest.py")

_EDITING_TEST = '''
from pathlib import Path

import tactileskin


def test_an_editor_saves_a_module():
    src = Path(tactileskin.__file__).parent / "report" / "array_chart.py"
    src.write_text(src.read_text() + "\\n# edited while the tests ran\\n")
'''


def _session(tmp_path, test_text):
    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    tests = tmp_path / "tests"
    tests.mkdir()
    shutil.copy(CONFTEST, tests / "conftest.py")
    (tests / "test_inner.py").write_text(test_text)
    env = dict(os.environ, PYTHONPATH=str(pkg))
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                           str(tests)], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)


def test_sources_edited_during_the_session_are_named_in_its_summary(tmp_path):
    r = _session(tmp_path, _EDITING_TEST)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "tactileskin's sources changed during this test run (report/array_chart.py)" in r.stdout, r.stdout


def test_an_unchanged_package_adds_nothing(tmp_path):
    r = _session(tmp_path, "def test_nothing():\n    pass\n")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "sources changed" not in r.stdout, r.stdout


def test_a_package_that_does_not_import_leaves_the_session_running(tmp_path):
    # without the package importable (not installed, a dependency missing) the tests that need
    # it fail at collection with its ImportError; the session-start hook must not abort the
    # whole run with an INTERNALERROR traceback (the tests that do not need it run)
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "tactileskin.py").write_text("raise ImportError('numba is not installed (simulated)')\n")
    tests = tmp_path / "tests"
    tests.mkdir()
    shutil.copy(CONFTEST, tests / "conftest.py")
    (tests / "test_inner.py").write_text("def test_nothing():\n    pass\n")
    env = dict(os.environ, PYTHONPATH=str(broken))
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                        str(tests)], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert r.returncode == 0 and "INTERNALERROR" not in r.stdout + r.stderr, r.stdout + r.stderr
    assert "1 passed" in r.stdout, r.stdout
