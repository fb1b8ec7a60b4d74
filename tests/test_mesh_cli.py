"""`tactileskin mesh` in-process: table, export, user errors."""

from __future__ import annotations

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


def test_mesh_command_rejects_bad_requests(tmp_path, capsys):
    assert main(["mesh", "--mesh-size", "0.002", "--refinement", "20", "--out", str(tmp_path / "m.vtu")]) == 2
    err = capsys.readouterr().err
    assert "mesh_size" in err and "Traceback" not in err
    assert main(["mesh", "--out", str(tmp_path / "m.stl")]) == 2
    assert ".msh, .vtu, .inp" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
