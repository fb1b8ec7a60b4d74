"""CPU cost of what a sweep writes after its last solve (report.outputs.write_outputs): each
figure drawn and saved per format, each render, the Parquet tables, and the imports they need,
so that the 2-core budget of issue 13's T10 (`./dev run` <= 4 s) is spent where it shows.

The records are the paper sweep's 18 cases at a quality preset, solved into --cache once (or
read from it). Every number is CPU seconds of this process (time.process_time), the median of
--repeat drawings after one warm-up drawing; the imports are timed in fresh processes (after
tactileskin.cli, as the command has it). Within a savefig, the constrained layout
(ConstrainedLayoutEngine.execute) and the PNG encoding (PIL Image.save: zlib) are timed apart;
"draw" is the rest (the backend drawing every artist).

    .venv/bin/python benchmarks/outputs_cost.py [--quality preview] [--cache /tmp/outputs_cost] [--repeat 5]
"""

from __future__ import annotations

import argparse
import io
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

# (module, imported before it): what each costs on top of what the process has by then
IMPORTS = (("matplotlib.pyplot", None), ("pyarrow.parquet", None), ("pandas", "pyarrow.parquet"),
           ("mpl_toolkits.axes_grid1.anchored_artists", "matplotlib.pyplot"),
           ("matplotlib.backends.backend_pdf", "matplotlib.pyplot"), ("meshio", "matplotlib.pyplot"),
           ("pyvista", "matplotlib.pyplot"))


def parquet_cold(tables: Path, repeat: int) -> tuple[float, bool]:
    """Median CPU seconds of writing results.parquet and profiles.parquet (the pickled rows in
    `tables`) in a fresh process, its imports included, and whether pandas was imported."""
    code = ("import pickle, sys, tempfile, time\n"
            "from pathlib import Path\n"
            "import tactileskin.cli, tactileskin.sweep\n"
            "from tactileskin.report import outputs\n"
            f"tables = pickle.loads(Path({str(tables)!r}).read_bytes())\n"
            "d = Path(tempfile.mkdtemp())\n"
            "t = time.process_time()\n"
            "for name, columns, rows in tables: outputs._write_parquet(d / name, columns, rows)\n"
            "print(time.process_time() - t, 'pandas' in sys.modules)")
    runs = [subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.split()
            for _ in range(repeat)]
    return statistics.median(float(r[-2]) for r in runs), runs[-1][-1] == "True"


def import_cpu(module: str, after: str | None, repeat: int) -> float:
    """Median CPU seconds of `import module` in a fresh process that imported tactileskin.cli
    and `after`."""
    code = ("import time, tactileskin.cli, tactileskin.sweep, tactileskin.report.outputs\n"
            + (f"import {after}\n" if after else "")
            + f"t = time.process_time(); import {module}; print(time.process_time() - t)")
    return statistics.median(float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                                  text=True).stdout.split()[-1]) for _ in range(repeat))


class Parts:
    """CPU seconds spent in the constrained layout and in PIL's PNG save, by the current label."""

    def __init__(self) -> None:
        import matplotlib.layout_engine as le
        from PIL import Image

        self.acc: dict[str, float] = defaultdict(float)
        for owner, name, part in ((le.ConstrainedLayoutEngine, "execute", "layout"), (Image.Image, "save", "encode")):
            self._wrap(owner, name, part)

    def _wrap(self, owner, name, part) -> None:
        fn = getattr(owner, name)

        def timed(*a, **kw):
            t = time.process_time()
            try:
                return fn(*a, **kw)
            finally:
                self.acc[part] += time.process_time() - t

        setattr(owner, name, timed)

    def take(self) -> dict[str, float]:
        out, self.acc = dict(self.acc), defaultdict(float)
        return out


# other settings for the same figures, measured and not used: (name, format, rc, savefig kwargs)
ALTERNATIVES = (
    ("PNG zlib level 6 (Pillow's default, used)", "png", {}, {}),
    ("PNG zlib level 1", "png", {}, {"pil_kwargs": {"compress_level": 1}}),
    ("SVG text as text (svg.fonttype none, used)", "svg", {}, {}),
    ("SVG text as paths (svg.fonttype path)", "svg", {"svg.fonttype": "path"}, {}),
    ("PDF Type 3 fonts (pdf.fonttype 3, used)", "pdf", {}, {}),
    ("PDF TrueType fonts (pdf.fonttype 42)", "pdf", {"pdf.fonttype": 42}, {}),
)


def alternatives(records, rows, repeat: int) -> dict[str, tuple[float, float]]:
    """CPU seconds and kB of saving the five sweep figures once in each ALTERNATIVES setting
    (their layout already computed, as for a second format), medians of `repeat`."""
    import matplotlib

    from tactileskin.report import figures

    figs = []
    real = figures._save
    figures._save = lambda fig, out, stem: figs.append(fig) or []
    try:
        for job in figures.figure_jobs(records, rows):
            job(Path(tempfile.gettempdir()))
    finally:
        figures._save = real
    for fig in figs:  # the layout, as the first format computes it; then fixed
        fig.savefig(io.BytesIO(), format="png", dpi=150)
        fig.set_layout_engine("none")
    res = {}
    for name, fmt, rc, kw in ALTERNATIVES:
        times, size = [], 0
        for _ in range(repeat + 1):
            t, size = time.process_time(), 0
            with matplotlib.rc_context(rc):
                for fig in figs:
                    buf = io.BytesIO()
                    fig.savefig(buf, format=fmt, dpi=150, **kw)
                    size += len(buf.getvalue())
            times.append(time.process_time() - t)
        res[name] = (statistics.median(times[1:]), size / 1024)
    for fig in figs:
        figures._plt().close(fig)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--cache", default=str(Path(tempfile.gettempdir()) / "outputs_cost"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()

    from tactileskin.cli.sweep import scenes_from_options
    from tactileskin.report import figures, outputs, render
    from tactileskin.sweep import ResultCache, run_sweep

    cache = ResultCache(Path(a.cache))
    outcomes = run_sweep(scenes_from_options({"quality": a.quality}), cache)
    records, rows, failures = outputs.collect(outcomes, cache)
    assert not failures, failures

    imports = {(m, after): import_cpu(m, after, a.repeat) for m, after in IMPORTS}
    prof = list(outputs.profile_rows(records))
    cols = outputs.RESULT_COLUMNS + ["dim", "variant"]
    with tempfile.TemporaryDirectory() as d:
        tables = Path(d) / "tables.pickle"
        tables.write_bytes(pickle.dumps([("results.parquet", cols, rows),
                                         ("profiles.parquet", outputs.PROFILE_COLUMNS, prof)]))
        cold, pandas = parquet_cold(tables, a.repeat)
    figures._plt()
    parts = Parts()
    cost: dict[tuple[str, str], list[float]] = defaultdict(list)  # (item, column) -> CPU s per repetition
    real_save = figures.save_reproducibly
    label = {"item": ""}

    def timed_save(fig, buf, fmt, dpi):
        parts.take()
        t = time.process_time()
        real_save(fig, buf, fmt, dpi)
        used, p = time.process_time() - t, parts.take()
        cost[(label["item"], fmt)].append(used)
        for k, v in p.items():
            cost[(label["item"], f"{fmt} {k}")].append(v)
        cost[(label["item"], f"{fmt} bytes")].append(len(buf.getvalue()))

    figures.save_reproducibly = timed_save
    for rep in range(a.repeat + 1):
        if rep == 1:  # the first drawing warms the font and text caches
            cost.clear()
        with tempfile.TemporaryDirectory() as d:
            out = Path(d)
            for job in figures.figure_jobs(records, rows):
                label["item"] = job.args[3] if job.func is figures.metric_figure else job.func.__name__
                t = time.process_time()
                job(out)
                cost[(label["item"], "total")].append(time.process_time() - t)
            for rec in [r for r in records if r.scene.indenter.value == "flat"
                        and r.scene.thickness == min(x.scene.thickness for x in records)]:
                item = f"render {rec.case}"
                t = time.process_time()
                fig = render.render_figure(rec.path / "result.vtu", rec.case, rec.scene)
                cost[(item, "build")].append(time.process_time() - t)
                parts.take()
                t = time.process_time()
                fig.savefig(io.BytesIO(), format="png", dpi=150)
                cost[(item, "png")].append(time.process_time() - t)
                for k, v in parts.take().items():
                    cost[(item, f"png {k}")].append(v)
                figures._plt().close(fig)
                cost[(item, "total")].append(cost[(item, "build")][-1] + cost[(item, "png")][-1])
            for name, columns, data in (("results.parquet", cols, rows), ("profiles.parquet", outputs.PROFILE_COLUMNS, prof)):
                t = time.process_time()
                outputs._write_parquet(out / name, columns, data)
                cost[(name, "total")].append(time.process_time() - t)

    figures.save_reproducibly = real_save
    alt = alternatives(records, rows, a.repeat)
    med = {k: statistics.median(v) for k, v in cost.items()}
    items = list(dict.fromkeys(k[0] for k in cost))
    print(f"{len(rows)} cases at {a.quality}; CPU seconds, medians of {a.repeat} (after one warm-up)\n")
    print("| item | total | build | PNG (layout + draw + encode) | SVG (layout + draw) | PDF (layout + draw) |")
    print("|---|---|---|---|---|---|")

    def fmt_cell(item: str, f: str) -> str:
        if (item, f) not in med:
            return ""
        lay, enc = med.get((item, f"{f} layout"), 0.0), med.get((item, f"{f} encode"), 0.0)
        split = f"{lay:.3f} + {med[(item, f)] - lay - enc:.3f}" + (f" + {enc:.3f}" if f == "png" else "")
        size = f", {med[(item, f + ' bytes')] / 1024:.0f} kB" if (item, f + " bytes") in med else ""
        return f"{med[(item, f)]:.3f} ({split}{size})"

    for item in items:
        build = med[(item, "build")] if (item, "build") in med else (
            med[(item, "total")] - sum(med.get((item, f), 0.0) for f in ("png", "svg", "pdf")))
        print(f"| {item} | {med[(item, 'total')]:.3f} | {build:.3f} | {fmt_cell(item, 'png')} "
              f"| {fmt_cell(item, 'svg')} | {fmt_cell(item, 'pdf')} |")
    total = sum(med[(i, "total")] for i in items)
    print(f"| **all** | **{total:.3f}** | | {sum(med.get((i, 'png'), 0) for i in items):.3f} "
          f"(encode {sum(med.get((i, 'png encode'), 0) for i in items):.3f}) "
          f"| {sum(med.get((i, 'svg'), 0) for i in items):.3f} | {sum(med.get((i, 'pdf'), 0) for i in items):.3f} |")
    print(f"\nlayout (constrained, all formats): {sum(v for k, v in med.items() if k[1].endswith('layout')):.3f} s\n")
    print("| the five figures saved once more in | CPU s | kB |")
    print("|---|---|---|")
    for name, (secs, kb) in alt.items():
        print(f"| {name} | {secs:.3f} | {kb:.0f} |")
    print()
    print("| import (fresh process, after tactileskin.cli) | after | CPU s |")
    print("|---|---|---|")
    print(f"| pyarrow + both tables written (pandas imported: {'yes' if pandas else 'no'}) | | {cold:.3f} |")
    for (m, after), s in imports.items():
        print(f"| {m} | {after or ''} | {s:.3f} |")


if __name__ == "__main__":
    main()
