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
