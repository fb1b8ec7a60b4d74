"""A read-only install (package folder, ~/.cache and NUMBA_CACHE_DIR all unwritable) must still
import and run the compiled modules: compiled in memory, one log line saying so. Tests run as
root (folder modes are ignored), so numba is told to use only the NUMBA_CACHE_DIR locator with
NUMBA_CACHE_DIR unset or unusable: the 'no locator available' condition."""

import os
import subprocess
import sys

import pytest

COMPILED = ["tactileskin.fe._kernels_nb", "tactileskin.fe._sparse_nb",
            "tactileskin.materials._prony_nb", "tactileskin.materials._hyperfoam_nb"]

CODE = """
import logging, sys
logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="LOG %(name)s %(message)s")
import numpy as np
import tactileskin.fe
{imports}
from tactileskin.materials.hyperfoam import Hyperfoam
print("ok")
"""


def _run(extra_env):
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env.update(extra_env)
    code = CODE.format(imports="\n".join(f"import {m}" for m in COMPILED))
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          timeout=600)


@pytest.mark.parametrize("cache_dir", [None, "/dev/null/numba"])
def test_compiled_modules_import_without_a_cache_folder(cache_dir):
    env = {"NUMBA_CACHE_LOCATOR_CLASSES": "UserProvidedCacheLocator"}
    if cache_dir:
        env["NUMBA_CACHE_DIR"] = cache_dir
    r = _run(env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.strip().endswith("ok")
    notes = [line for line in r.stderr.splitlines() if line.startswith("LOG") and "cache" in line]
    assert len(notes) == 1, r.stderr[-2000:]
    assert "NUMBA_CACHE_DIR" in notes[0]


def test_no_note_when_the_cache_works():
    r = _run({})
    assert r.returncode == 0, r.stderr[-2000:]
    assert not [line for line in r.stderr.splitlines() if line.startswith("LOG") and "cache" in line]
