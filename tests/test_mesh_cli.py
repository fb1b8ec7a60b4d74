"""`tactileskin mesh` in-process: table, export, user errors."""

from __future__ import annotations

from pathlib import Path

import meshio

from tactileskin.cli import main


def test_mesh_command_writes_vtu_and_prints_table(tmp_path, capsys):
    out = tmp_path / "mesh.vtu"
    rc = main(["mesh", "--thickness", "3", "--indenter", "braille", "--mesh-size", "0.5", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    assert "P2 triangles" in text and "bone_interface" in text and "min scaled Jacobian" in text
    m = meshio.read(out)
    assert len(m.get_cells_type("triangle6")) > 100
    # the boundaries keep their names (VTK field data: name -> [gmsh physical id, dim]), as in
    # result.vtu; the file had bare integers only
    import re

    names = dict(re.findall(r'<DataArray type="Int32" Name="(\w+)" NumberOfTuples="1" NumberOfComponents="2" '
                            r'format="ascii">(\d+) 1</DataArray>', out.read_text()))
    assert {"bone_interface", "outer_surface", "symmetry", "nail_edge"} <= set(names)
    ids = m.cell_data["gmsh:physical"][1]                 # the boundary facets' ids
    assert {int(v) for v in names.values()} == set(ids.tolist())


def test_mesh_command_3d(tmp_path, capsys):
    out = tmp_path / "slab.msh"
    rc = main(["mesh", "-t", "5", "--dim", "3", "--mesh-size", "1.5", "--refinement", "1.5", "--out", str(out)])
    assert rc == 0
    assert "P2 tetrahedra" in capsys.readouterr().out and "end_front" in meshio.read(out).field_data


def test_mesh_command_table_names_the_boundaries_as_the_file_does(tmp_path, capsys):
    # a z-symmetric slab's mid-plane is written as symmetry_z; the table called it end_back,
    # a name the file does not have
    out = tmp_path / "slab.vtu"
    assert main(["mesh", "-t", "1", "--dim", "3", "--quality", "preview", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    names = set(meshio.read(out).field_data) - {"skin"}
    assert "symmetry_z" in names
    assert all(f"facets: {n}" in text for n in names), text
    assert "end_back" not in text


def test_mesh_command_rejects_bad_requests(tmp_path, capsys):
    assert main(["mesh", "--mesh-size", "0.002", "--refinement", "20", "--out", str(tmp_path / "m.vtu")]) == 2
    err = capsys.readouterr().err
    assert "mesh_size" in err and "Traceback" not in err
    assert main(["mesh", "--out", str(tmp_path / "m.stl")]) == 2
    assert ".msh, .vtu, .inp" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_mesh_command_bone_interface_length_agrees_with_cad_for_every_skin(capsys):
    """The table's check of the bonded length against the CAD. The dome's bone_interface
    covers its straight part (z in [-L, 0], L = dome_length) only, but was divided by the
    whole skin's length L + dome_tip: 9.619 mm against the CAD's 17.314 (rel. err 4.4e-01)
    for a correct mesh."""
    import re

    for args in (["--skin", "dome", "-t", "2", "-i", "sphere", "--indenter-radius", "2.5"],
                 ["-t", "3", "--dim", "3", "-i", "flat"],
                 # not mirror-symmetric about x = 0: the pad is modelled in full width (20 mm
                 # bonded), which was compared with the half width's 10 (rel. err 1.0e+00)
                 ["--skin", "pad", "-t", "1", "--dim", "3", "-i", "braille", "--braille-text", "ab"]):
        rc = main(["mesh", *args, "--mesh-size", "2", "--refinement", "2"])
        text = capsys.readouterr().out
        assert rc == 0
        err = float(re.search(r"bone interface length \(mm\).*rel\. err ([0-9.e+-]+)\)", text).group(1))
        assert err < 1e-3, (args, text)


def _no_mesh(monkeypatch):
    import tactileskin.mesh

    calls = []

    def build_mesh(*a, **kw):  # the checks must refuse before this
        calls.append(a)
        raise AssertionError("meshed before the output was checked")

    monkeypatch.setattr(tactileskin.mesh, "build_mesh", build_mesh)
    return calls


def test_mesh_command_refuses_an_unwritable_out_before_meshing(tmp_path, capsys, monkeypatch):
    """`mesh -o afile/m.msh` (a file where its folder should be) printed the whole table, then
    'cannot write afile'; the folder is now checked before the mesh is made, nothing printed."""
    calls = _no_mesh(monkeypatch)
    (tmp_path / "afile").write_text("mine\n")
    assert main(["mesh", "--quality", "preview", "-o", str(tmp_path / "afile" / "m.msh")]) == 2
    cap = capsys.readouterr()
    assert calls == [] and cap.out == "" and "afile" in cap.err and "Traceback" not in cap.err
    assert (tmp_path / "afile").read_text() == "mine\n"


def test_mesh_command_refuses_a_linked_record_lock_before_meshing(tmp_path, capsys, monkeypatch):
    """A symlink named .tactileskin-files.lock in the folder of --out was refused only when the
    mesh was written, after its table; now before the mesh is made, naming the link."""
    from tactileskin import ownership

    calls = _no_mesh(monkeypatch)
    d = tmp_path / "d"
    d.mkdir()
    (d / ownership.RECORD_LOCK).symlink_to(tmp_path / "elsewhere")
    assert main(["mesh", "--quality", "preview", "-o", str(d / "m.msh")]) == 2
    cap = capsys.readouterr()
    assert calls == [] and cap.out == "" and "symbolic link" in cap.err and ownership.RECORD_LOCK in cap.err
    assert not (tmp_path / "elsewhere").exists() and [p.name for p in d.iterdir()] == [ownership.RECORD_LOCK]


def test_mesh_command_refuses_a_read_only_folder_before_meshing(tmp_path, capsys, monkeypatch):
    """A folder where no file can be made (root ignores folder modes: mkstemp refused there
    stands for read-only) is refused before the mesh is made."""
    import errno
    import tempfile

    calls = _no_mesh(monkeypatch)
    d = tmp_path / "ro"
    d.mkdir()
    real = tempfile.mkstemp

    def mkstemp(*a, dir=None, **kw):
        if dir is not None and Path(dir) == d:
            raise PermissionError(errno.EACCES, "Permission denied", str(dir))
        return real(*a, dir=dir, **kw)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    assert main(["mesh", "--quality", "preview", "-o", str(d / "m.msh")]) == 2
    cap = capsys.readouterr()
    assert calls == [] and cap.out == "" and "permission denied" in cap.err and str(d) in cap.err
    assert list(d.iterdir()) == []


def test_the_writability_probe_is_removed_when_interrupted(tmp_path, monkeypatch):
    """check_writable makes a temporary in the user's folder to see a file can be made there; a
    Ctrl-C between making it and removing it (here at its os.close) left it behind in their folder."""
    import os

    import pytest

    from tactileskin import ownership

    d = tmp_path / "d"
    d.mkdir()
    real = os.close

    def close(fd):
        real(fd)
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "close", close)
    with pytest.raises(KeyboardInterrupt):
        ownership.check_writable(d / "m.msh")
    monkeypatch.setattr(os, "close", real)
    assert list(d.iterdir()) == []
