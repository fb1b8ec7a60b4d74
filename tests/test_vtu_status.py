"""result.vtu says whether its result is suspect, as summary.json and every CSV of the folder do:
a numeric cell array `suspect` (1 on every cell of a suspect result, 0 of an ok one; ParaView
lists and colours it, and meshio reads it, which refuses string arrays) and summary.json's
status text in an XML comment before the grid (every VTK and meshio reader skips it). The
package's readers (renders, probes, charts) read the file as before."""

from __future__ import annotations

import json
import re

import meshio
import numpy as np
import pytest

from tactileskin import quality
from tactileskin.fe import solve
from tactileskin.fe.probe import result_sampler
from tactileskin.planner import with_quality
from tactileskin.report.render import render_case
from tactileskin.results import SUSPECT_ARRAY, read_vtu, vtu_status
from tactileskin.scene import Scene

OK = with_quality(Scene(thickness=3.0, indenter="curved"), "preview")
# coarser than the preview preset: suspect, with contact (test_status_columns' COARSE_2D)
SUSPECT = Scene(thickness=3.0, indenter="curved", mesh_size=2.0, refinement=2)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = {}
    for name, sc in (("ok", OK), ("suspect", SUSPECT)):
        res = solve(sc, history=True)
        out[name] = (res, res.write(tmp_path_factory.mktemp(name) / "r"))
    return out


def test_an_ok_and_a_suspect_result_differ_in_the_file(written):
    for name, (res, out) in written.items():
        status = json.loads((out / "summary.json").read_text())["status"]
        assert quality.kind(status) == name, status
        m = meshio.read(out / "result.vtu")
        flag = m.cell_data[SUSPECT_ARRAY]
        assert [len(b) for b in flag] == [len(c.data) for c in m.cells]  # every cell, boundaries too
        assert {int(v) for b in flag for v in np.unique(b)} == {int(name == "suspect")}
        # the status text, summary.json's, as the file holds it and reads back
        assert vtu_status(out / "result.vtu") == status
        text = (out / "result.vtu").read_text(encoding="utf-8")
        assert "<!-- tactileskin status: " in text
        # a comment may not hold "--" (XML): the file is still well-formed
        import xml.etree.ElementTree as ET

        ET.parse(out / "result.vtu")
        # the increments of result.pvd belong to the same result
        for step in sorted((out / "result_steps").glob("step_*.vtu")):
            assert vtu_status(step) == status
            sm = meshio.read(step)
            assert {int(v) for b in sm.cell_data[SUSPECT_ARRAY] for v in np.unique(b)} == {int(name == "suspect")}


def test_a_status_holding_double_dashes_round_trips(written, tmp_path):
    """The coarse-mesh reason says "use --quality": an XML comment cannot hold "--"."""
    res, out = written["suspect"]
    status = res.summary()["status"]
    assert "--" in status
    assert vtu_status(out / "result.vtu") == status


def test_the_files_round_trip_and_the_packages_readers_read_them(written, tmp_path):
    for name, (res, out) in written.items():
        vtu = out / "result.vtu"
        m = read_vtu(vtu)
        # meshio writes back what it read (the flag included) and reads that again
        meshio.write(tmp_path / f"{name}.vtu", m)
        back = meshio.read(tmp_path / f"{name}.vtu")
        np.testing.assert_array_equal(back.points, m.points)
        for k in m.cell_data:
            for a, b in zip(back.cell_data[k], m.cell_data[k]):
                np.testing.assert_array_equal(a, b)
        assert set(back.point_data) == set(m.point_data)
        # field data holds the boundary names only (the flag is no boundary)
        assert set(m.field_data) == set(res.fields["boundaries"])
        # the probe's stresses at the nodes are the file's
        X = m.points[:5, :2]
        sig = result_sampler(vtu)(X)
        np.testing.assert_allclose(sig[:, 0, 0], m.point_data["sxx_MPa"][:5], rtol=1e-9, atol=1e-12)
        png = render_case(vtu, tmp_path / f"{name}.png", title=name)
        assert png.read_bytes()[:4] == b"\x89PNG"


def test_a_file_without_the_comment_has_no_status(tmp_path):
    p = tmp_path / "x.vtu"
    meshio.write(p, meshio.Mesh(np.zeros((3, 3)), [("triangle", np.array([[0, 1, 2]]))]))
    assert vtu_status(p) is None


def test_to_pyvista_carries_the_flag(written):
    pytest.importorskip("pyvista")
    for name, (res, out) in written.items():
        grid = res.to_pyvista()
        assert set(np.unique(grid.cell_data[SUSPECT_ARRAY]).tolist()) == {int(name == "suspect")}
        assert not re.search("suspect|status", " ".join(grid.field_data.keys()))


@pytest.mark.parametrize("status", [
    "suspect: sensor '\x01a\x1b[31m' \\u0041 \\x-- end\r\nnext\tline -",
    "suspect: \ud800 lone surrogate, \ufffe\uffff not characters, \x7f\x85 kept, \\\\ -->",
])
def test_a_status_with_control_characters_is_valid_xml_and_round_trips(tmp_path, status):
    """XML 1.0 allows no control character but tab, newline and CR (a parser turns CR LF into
    LF) and no U+FFFE, U+FFFF; a lone surrogate cannot be UTF-8 at all. A status text holding
    one (a name given by the user in a reason) made result.vtu invalid XML, or failed the write."""
    import xml.etree.ElementTree as ET

    from tactileskin.results import _write_vtu

    fields = {"points": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), "cell_type": "triangle",
              "cells": np.array([[0, 1, 2]]), "point_data": {}}
    p = tmp_path / "result.vtu"
    _write_vtu(p, fields, status=status)
    ET.parse(p)
    assert vtu_status(p) == status
    assert meshio.read(p).cell_data[SUSPECT_ARRAY][0].tolist() == [1]


def test_a_status_longer_than_the_first_64_kib_reads_back(tmp_path):
    """vtu_status read only the file's first 64 KiB: the comment starts there (after the XML
    declaration, whatever the mesh's size) but a status longer than that (a user's names in
    its reasons) ended past it and read back as None, a suspect result looking plain."""
    from tactileskin.results import _write_vtu

    fields = {"points": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), "cell_type": "triangle",
              "cells": np.array([[0, 1, 2]]), "point_data": {}}
    status = "suspect: sensor '" + "s" * 70_000 + "' off the skin -- use --quality"
    p = tmp_path / "result.vtu"
    _write_vtu(p, fields, status=status)
    assert vtu_status(p) == status


def test_a_status_comment_without_its_end_is_read_in_linear_time(tmp_path):
    """A damaged file whose status comment never ends (cut off, or edited) is read to its end to
    answer None; appending each 64 KiB chunk to an immutable bytes copied all read so far, so a
    32 MiB file took ~9 s (64 MiB: 34 s; a large 3D result's hundreds of MiB: many minutes)."""
    import time

    p = tmp_path / "result.vtu"
    with open(p, "wb") as fh:
        fh.write(b'<?xml version="1.0"?>\n<!-- tactileskin status: suspect: x')
        fh.write(b"A" * (32 << 20))
    c0 = time.process_time()
    assert vtu_status(p) is None
    assert time.process_time() - c0 < 2.0


def test_an_old_status_with_a_separator_inside_a_reason_is_counted_by_its_flags(tmp_path):
    """result.vtu written before quality.Flag turned '; ' into ', ' hold reasons like 'refining does
    not cure it; use order 2': split on '; ' they counted one reason too many in '(+N more)'. The
    summary.json beside the file lists the flags, so their reasons are the ones counted."""
    from tactileskin.report.render import _titled
    from tactileskin.results import _write_vtu

    reasons = ["linear (P1) displacement elements with a nearly incompressible law lock, and refining does "
               "not cure it; use order 2", "stress 9 MPa beyond 5 MPa", "volume ratio J = 0.2 outside [0.3, 3]"]
    status = "suspect: " + "; ".join(reasons)
    fields = {"points": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), "cell_type": "triangle",
              "cells": np.array([[0, 1, 2]]), "point_data": {}}
    _write_vtu(tmp_path / "result.vtu", fields, status=status)
    (tmp_path / "summary.json").write_text(json.dumps(
        {"status": status, "flags": [{"code": c, "reason": r} for c, r in zip(("locking", "stress_range",
                                                                                "volume_range"), reasons)]}))
    title = _titled(tmp_path / "result.vtu", "t", 40)
    assert "(+2 more)" in title and "(+3 more)" not in title
    # a summary.json of another status (the folder rewritten) is not used: the status is split
    (tmp_path / "summary.json").write_text(json.dumps({"status": "ok", "flags": []}))
    assert "(+3 more)" in _titled(tmp_path / "result.vtu", "t", 40)
