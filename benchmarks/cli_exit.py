"""Time the console script's end: `cli.run` (exit handlers, flush, os._exit) against
`sys.exit(cli.main())` (Python's full teardown), interleaved, on a command given after `--`
(default: a cached rerun of the preview sweep into --out, solved once first).

    .venv/bin/python benchmarks/cli_exit.py [--repeat 7] [--out /tmp/cli_exit] [-- tactileskin args]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ENDS = {"cli.run (os._exit after the exit handlers)": "from tactileskin.cli import run; run()",
        "sys.exit(cli.main())": "import sys; from tactileskin.cli import main; sys.exit(main())"}


def once(code: str, args: list[str]) -> tuple[float, float, int]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    rc = subprocess.run([sys.executable, "-c", f"import sys; sys.argv = ['tactileskin'] + {args!r}; {code}"],
                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime), rc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--out", default=str(Path(tempfile.gettempdir()) / "cli_exit"))
    ap.add_argument("args", nargs="*")
    a = ap.parse_args()
    args = a.args or ["sweep", "--out", a.out, "--quality", "preview"]
    once(ENDS["sys.exit(cli.main())"], args)  # solves into the cache if needed
    got = {k: [] for k in ENDS}
    for _ in range(a.repeat):
        for name, code in ENDS.items():
            got[name].append(once(code, args))
    print(f"`tactileskin {' '.join(args)}`, medians of {a.repeat}, interleaved\n")
    print("| end | wall (s) | CPU (s) | exit codes |")
    print("|---|---|---|---|")
    for name, runs in got.items():
        print(f"| {name} | {statistics.median(w for w, _, _ in runs):.2f} | {statistics.median(c for _, c, _ in runs):.2f} "
              f"| {sorted({rc for _, _, rc in runs})} |")


if __name__ == "__main__":
    main()
