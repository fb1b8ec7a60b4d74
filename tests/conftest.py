"""Test-session settings: one BLAS/OpenMP thread per pytest-xdist worker (as the CLI does),
so two workers on two cores do not oversubscribe them."""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
