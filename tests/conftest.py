"""Test-session settings: one BLAS/OpenMP thread per pytest-xdist worker (as the CLI does),
so two workers on two cores do not oversubscribe them."""

import os
import sys

import pytest

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


@pytest.fixture
def close_figures():
    """Close every pyplot figure after the test: a test whose stub of the figures' `_save` keeps
    the figures skips the close the library does (test_case_ids.py and test_report_figures.py left
    21 open, and matplotlib warned of more than 20 in the session)."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


def pytest_sessionstart(session):
    # the package's sources as this session starts (tactileskin's own import-time snapshot,
    # cache.code_changes compares against the same): an edit in the checkout under test while
    # the suite runs fails every test that caches a solve ('restart Python'), by design
    try:
        import tactileskin  # noqa: F401 (light: its heavy modules load on first use)
    except Exception:  # noqa: BLE001 - not importable: the tests that need it fail at collection, saying why
        pass


def pytest_terminal_summary(terminalreporter):
    pkg = sys.modules.get("tactileskin")
    if pkg is None or not hasattr(pkg, "_IMPORTED_SOURCES"):
        return
    now, then = pkg._source_hashes(), pkg._IMPORTED_SOURCES
    changed = sorted(k for k in now.keys() | then.keys() if now.get(k) != then.get(k))
    if changed:
        names = ", ".join(changed[:5]) + (f" and {len(changed) - 5} more" if len(changed) > 5 else "")
        terminalreporter.write_line(
            f"tactileskin's sources changed during this test run ({names}): the tests that cache a solve "
            "fail then by design (cache.code_changes); rerun on a checkout nobody edits meanwhile", yellow=True)
