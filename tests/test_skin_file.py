"""A user's skin from a file (skins.file, mesh.skinfile): a .msh with named groups solves like the
built-in pad on the same mesh; a STEP solid is meshed with its bonded faces by a rule; the cache
key follows the file's bytes; clear errors for missing groups, open solids, wrong units."""

import re
import shutil

import numpy as np
import pytest

from tactileskin import cache, sensors
from tactileskin.errors import MeshError, ParameterError
from tactileskin.fe import solve
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

PAD = dict(skin="pad", pad_width=8.0, pad_length=8.0, thickness=2.0, indenter="flat",
           depth_fraction=0.03, viscoelastic=False, mesh_size=0.8, refinement=1.0)


def _gmsh_block(path, w=4.0, t=2.0, names=("bonded", "outer_surface"), dim=3, order=1, mixed=False):
    """A block x in [0, w], y in [0, t] (z in [-w/2, w/2] in 3D: across the indenters' axis) written by gmsh with physical groups:
    the bottom names[0], the top names[1], x = 0 `symmetry`, the rest `sides`."""
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("block")
        occ = gmsh.model.occ
        if dim == 3:
            occ.addBox(0, 0, -w / 2, w, t, w)
        elif mixed:  # two halves, one of them recombined into quadrilaterals
            occ.fragment([(2, occ.addRectangle(0, 0, 0, w / 2, t))], [(2, occ.addRectangle(w / 2, 0, 0, w / 2, t))])
        else:
            occ.addRectangle(0, 0, 0, w, t)
        occ.synchronize()
        groups = {names[0]: [], names[1]: [], "symmetry": [], "sides": []}
        for _, f in gmsh.model.getEntities(dim - 1):
            c = occ.getCenterOfMass(dim - 1, f)
            if gmsh.model.getAdjacencies(dim - 1, f)[0].size > 1:
                continue  # the interface between the halves
            key = (names[0] if abs(c[1]) < 1e-9 else names[1] if abs(c[1] - t) < 1e-9
                   else "symmetry" if abs(c[0]) < 1e-9 else "sides")
            groups[key].append(f)
        for name, ents in groups.items():
            if name and ents:
                gmsh.model.addPhysicalGroup(dim - 1, ents, name=name)
        gmsh.model.addPhysicalGroup(dim, [e for _, e in gmsh.model.getEntities(dim)], name="skin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
        if mixed:
            gmsh.model.mesh.setRecombine(2, gmsh.model.getEntities(2)[0][1])
        gmsh.model.mesh.generate(dim)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def test_msh_of_the_pad_mesh_solves_like_the_pad(tmp_path):
    """Same mesh -> same answer: the pad's own mesh written as .msh and read back as a file skin
    gives the same reaction and bone profile (to 1e-10: only node numbering differs, and the
    solver's stopping tests are relative to 1e-10 or tighter)."""
    pad = Scene(**PAD)
    sm = build_mesh(pad)
    path = sm.write(tmp_path / "pad.msh")
    user = Scene(skin="file", skin_file=str(path), indenter="flat", depth_fraction=0.03, viscoelastic=False)
    assert user.dim == 2 and user.thickness == pytest.approx(2.0, abs=1e-12)
    assert user.section().top == pytest.approx(2.0, abs=1e-12)
    um = build_mesh(user)
    assert set(um.boundaries) >= {"bone_interface", "outer_surface", "symmetry", "side"}
    assert um.measure() == pytest.approx(sm.measure(), rel=1e-12)
    a, b = solve(pad, mesh=sm), solve(user, mesh=um)
    assert b.reaction == pytest.approx(a.reaction, rel=1e-10)
    assert np.allclose(b.s, a.s, atol=1e-12)
    assert np.allclose(b.pressure, a.pressure, rtol=0, atol=1e-10 * np.abs(a.pressure).max())


def test_3d_quarter_pad_written_as_msh_solves_like_the_pad(tmp_path):
    """A z-symmetric 3D pad mesh (the quarter x, z >= 0) written as .msh names its mid-plane
    `symmetry_z`, which the file skin reads as u_z = 0: same mesh, same answer (it was read as a
    free end: a sphere's force 2.5x low and the peak off the axis, status ok)."""
    kw = dict(indenter="sphere", indenter_radius=2.5, depth=0.2, viscoelastic=False)
    pad = Scene(skin="pad", pad_width=6.0, pad_length=6.0, thickness=2.0, dim=3, mesh_size=1.0, refinement=3.0,
                **kw)
    sm = build_mesh(pad)
    assert sm.z_symmetric and sm.halved
    path = sm.write(tmp_path / "quarter.msh")
    user = Scene(skin="file", skin_file=str(path), **kw)
    um = build_mesh(user)
    assert um.z_symmetric and um.halved and "symmetry_z" not in um.boundaries
    a, b = solve(pad, mesh=sm), solve(user, mesh=um)
    assert b.reaction == pytest.approx(a.reaction, rel=1e-8)
    assert b.peak == pytest.approx(a.peak, rel=1e-8)
    assert b.status == "ok"


def test_a_symmetry_group_off_its_plane_is_refused(tmp_path):
    # the block's x = 0 face named `symmetry_z`: not on z = 0
    path = tmp_path / "b.msh"
    _gmsh_block(path)
    text = path.read_text().replace('"symmetry"', '"symmetry_z"')
    path.write_text(text)
    with pytest.raises(ParameterError, match="symmetry_z"):
        build_mesh(Scene(skin="file", skin_file=str(path), indenter="flat", viscoelastic=False))


def test_gmsh_written_block_maps_common_names_and_elevates_order(tmp_path):
    path = _gmsh_block(tmp_path / "block.msh", names=("board", "top"))
    sc = Scene(skin="file", skin_file=str(path), indenter="sphere", indenter_radius=2.0, depth=0.1,
               viscoelastic=False)
    assert sc.dim == 3 and sc.thickness == pytest.approx(2.0, abs=1e-12)  # the file fixes them
    sm = build_mesh(sc)  # order 1 in the file, P2 for the scene (straight mid-nodes)
    assert sm.order == 2 and sm.measure() == pytest.approx(32.0, rel=1e-12)
    assert sm.boundary_measure("bone_interface") == pytest.approx(16.0, rel=1e-12)
    assert sm.boundary_measure("outer_surface") == pytest.approx(16.0, rel=1e-12)
    assert sm.boundary_measure("sides") == pytest.approx(3 * 8.0, rel=1e-12)  # x = 4, z = -2, z = 2
    with pytest.raises(ParameterError, match=r"skin_bonded.*found: board, sides, symmetry, top"):
        Scene(skin="file", skin_file=str(path), skin_bonded="bottom")
    with pytest.raises(ParameterError, match=r"skin_outer.*no group named 'contact'"):
        Scene(skin="file", skin_file=str(path), skin_outer="contact")
    with pytest.raises(ParameterError, match="thickness.*measured"):
        Scene(skin="file", skin_file=str(path), thickness=1.5)
    # sensors (they were refused): a grid at depth 0.5 over the half model x >= 0 and its mirror
    # image, on the file's z extent [-2, 2]
    grid = {"name": "g", "kind": "grid", "s": [-1.0, 1.0], "z": [-2.0, 2.0], "pitch": [1.0, 2.0], "depth": 0.5}
    sites = sensors.sites_for(Scene(skin="file", skin_file=str(path), sensors=[grid]))
    assert np.allclose(sites.xyz[:, 1], 1.5) and np.allclose(sites.normal, [0.0, 1.0, 0.0])
    assert sorted(set(sites.xyz[:, 0])) == [-1.0, 0.0, 1.0] and sorted(set(sites.xyz[:, 2])) == [-2.0, 0.0, 2.0]
    with pytest.raises(ParameterError, match=r"'g' s, z=\(0.0, 2.5\) .*z in \[-2, 2\] mm.*sensor g-2: no skin"):
        Scene(skin="file", skin_file=str(path), sensors=[{**grid, "s": [0.0, 1.0], "z": [0.5, 2.5]}])


def test_no_bonded_group_wrong_units_and_mixed_cells(tmp_path):
    nob = _gmsh_block(tmp_path / "nob.msh", names=("bottom", "top"))
    with pytest.raises(ParameterError, match=r"skin_bonded.*found: bottom, sides, symmetry, top"):
        Scene(skin="file", skin_file=str(nob))
    metres = _gmsh_block(tmp_path / "m.msh", w=0.004, t=0.002)
    with pytest.raises(ParameterError, match=r"skin_file.*0.1 mm and 1 m.*metres"):
        Scene(skin="file", skin_file=str(metres))
    mixed = _gmsh_block(tmp_path / "mixed.msh", dim=2, mixed=True)
    with pytest.raises(MeshError, match="mixed element types"):
        Scene(skin="file", skin_file=str(mixed))


def test_a_bonded_group_inside_the_mesh_names_skin_bonded_and_the_file(tmp_path):
    """Two layers glued along y = 1, the glue line named as the bonded group: it lies between
    cells, not on the skin's boundary. The error named neither the parameter nor the file
    ("boundary 'bone_interface': a gmsh facet is not a boundary facet of the mesh")."""
    import gmsh

    path = tmp_path / "layers.msh"
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        occ.fragment([(2, occ.addRectangle(-2, 0, 0, 4, 1))], [(2, occ.addRectangle(-2, 1, 0, 4, 1))])
        occ.synchronize()
        glue = [c for _, c in gmsh.model.getEntities(1) if abs(occ.getCenterOfMass(1, c)[1] - 1.0) < 1e-9]
        gmsh.model.addPhysicalGroup(1, glue, name="glue")
        gmsh.model.addPhysicalGroup(2, [e for _, e in gmsh.model.getEntities(2)], name="skin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    with pytest.raises(ParameterError, match=r"skin_bonded='glue'.*layers\.msh.*'glue' lies inside the mesh"):
        Scene(skin="file", skin_file=str(path), skin_bonded="glue")


def test_cache_key_follows_bytes_not_path(tmp_path):
    a = _gmsh_block(tmp_path / "a.msh", dim=2)
    b = tmp_path / "sub" / "b.msh"
    b.parent.mkdir()
    shutil.copy(a, b)
    ka = cache.cache_key(Scene(skin="file", skin_file=str(a)))
    assert cache.cache_key(Scene(skin="file", skin_file=str(b))) == ka  # moved: same key
    _gmsh_block(b, dim=2, w=5.0)
    assert cache.cache_key(Scene(skin="file", skin_file=str(b))) != ka  # edited: new key


def test_a_cached_result_of_a_moved_skin_file_is_reused_not_called_damaged(tmp_path, caplog):
    import numpy as np

    from tactileskin.results import Result

    a = _gmsh_block(tmp_path / "a.msh", dim=2)
    rc = cache.ResultCache(tmp_path / "cache")
    res = Result(s=np.array([0.0, 1.0]), pressure=np.array([0.2, 0.0]), contact_x=np.zeros(0),
                 contact_pressure=np.zeros(0), reaction=0.1, stats={"dofs": 6})
    rc.store(Scene(skin="file", skin_file=str(a)), res)
    b = tmp_path / "sub" / "b.msh"
    b.parent.mkdir()
    shutil.move(a, b)  # same bytes, another name: the same key, and the entry is still good
    rec = rc.load(Scene(skin="file", skin_file=str(b)))
    assert rec is not None and rec.summary["peak_mpa"] == 0.2
    assert "damaged" not in caplog.text


def _step_block(path, w=4.0, t=2.0, open_=False):
    import build123d as bd

    box = bd.Box(w, t, w, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    shape = bd.Shell(box.faces()[:-1]) if open_ else box
    bd.export_step(shape, str(path))
    return path


def test_step_block_bonded_by_rule(tmp_path):
    path = _step_block(tmp_path / "block.step")
    sc = Scene(skin="file", skin_file=str(path), indenter="sphere", indenter_radius=2.0, depth=0.1,
               mesh_size=1.0, refinement=1.0)
    assert sc.dim == 3 and sc.thickness == pytest.approx(2.0, abs=1e-9)
    assert sc.section().top == pytest.approx(2.0, abs=1e-9)
    # whole: the symmetric block under the sphere is otherwise cut to its quarter (test_step_symmetry)
    sm = build_mesh(sc, use_symmetry=False)
    assert sm.boundary_measure("bone_interface") == pytest.approx(16.0, rel=1e-9)  # the face y = 0
    assert sm.boundary_measure("outer_surface") == pytest.approx(16.0 + 4 * 8.0, rel=1e-9)
    assert "symmetry" not in sm.boundaries  # a full model
    plane = build_mesh(sc.replace(skin_bonded="plane:y=0"), use_symmetry=False)
    assert plane.boundary_measure("bone_interface") == pytest.approx(16.0, rel=1e-9)
    with pytest.raises(ParameterError, match="skin_bonded.*no face matches"):
        Scene(skin="file", skin_file=str(path), skin_bonded="plane:y=-1")
    with pytest.raises(ParameterError, match="skin_bonded.*rule"):
        Scene(skin="file", skin_file=str(path), skin_bonded="bottom")


@pytest.mark.parametrize("rule", ["normal:-y:.", "normal:-y:1.2.3"])
def test_a_bonded_rule_with_a_malformed_tolerance_is_one_line(tmp_path, capsys, rule):
    """The rule's tolerance took any digits and dots: '--skin-bonded normal:-y:1.2.3' ended in
    float()'s ValueError traceback (exit 1); it is refused naming skin_bonded and the range."""
    from tactileskin.cli import main

    path = _step_block(tmp_path / "block.step")
    assert main(["mesh", "--skin-file", str(path), "--skin-bonded", rule, "--out", str(tmp_path / "m.msh")]) == 2
    err = capsys.readouterr().err
    assert f"skin_bonded={rule!r}" in err and "(0, 90) degrees" in err and "Traceback" not in err
    assert not (tmp_path / "m.msh").exists()


def test_open_step_is_refused(tmp_path):
    path = _step_block(tmp_path / "open.step", open_=True)
    with pytest.raises(ParameterError, match="skin_file.*one closed solid.*not closed"):
        Scene(skin="file", skin_file=str(path))


@pytest.mark.parametrize("shape", ["cap", "crown"])
def test_a_step_skins_top_is_its_point_on_the_axis(tmp_path, shape):
    """A sphere cap (radius 6) and a crown (a cylinder along z) 2 mm thick on a flat base: the
    top point, where indenters start and s = x - x_top is measured from, is the surface's point
    on the axis x = z = 0. It was the refined highest node of the coarse mesh: the cap's 0.34 mm
    off the axis (t read 1.990), the crown's at z = -3.2 along its top line."""
    import build123d as bd

    from tactileskin.skins.file import geometry

    round_ = bd.Sphere(6.0) if shape == "cap" else bd.Cylinder(6.0, 8.0)  # the cylinder's axis: z
    base = bd.Box(8.0, 2.0, 8.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    path = tmp_path / f"{shape}.step"
    bd.export_step(bd.Pos(0, -4.0, 0) * round_ & base, str(path))
    geo = geometry(Scene(skin="file", skin_file=str(path)))
    assert geo.top_point == (pytest.approx(0.0, abs=1e-9), pytest.approx(2.0, abs=1e-9), pytest.approx(0.0, abs=1e-9))
    assert geo.thickness == pytest.approx(2.0, abs=1e-9)


def test_step_block_solves_like_the_pad_block(tmp_path):
    """A STEP block (full model, no symmetry) bonded at y = 0 by the default rule and pressed by
    a flat plate carries the force of the pad's block of the same size, solved as a quarter (the
    reported force is the whole indenter's in both); different meshes of the same size h = 1 mm
    (measured 2.5e-4 apart), so 1e-3."""
    import build123d as bd

    path = tmp_path / "block.step"
    bd.export_step(bd.Box(8.0, 2.0, 8.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER)), str(path))
    kw = dict(indenter="flat", depth_fraction=0.03, viscoelastic=False, mesh_size=1.0, refinement=1.0)
    user = Scene(skin="file", skin_file=str(path), **kw)
    full = solve(user, mesh=build_mesh(user, use_symmetry=False))  # not cut to its quarter: the whole model
    quarter = solve(Scene(skin="pad", pad_width=8.0, pad_length=8.0, thickness=2.0, dim=3, **kw))
    assert quarter.stats["dofs"] < 0.5 * full.stats["dofs"]  # it was the quarter
    assert full.reaction == pytest.approx(quarter.reaction, rel=1e-3)
    # the whole block's profile runs across the centre: half its extent is the quarter's span
    # (the plate presses the whole top: the pad's half width); its AUC on these 1 mm cells is
    # left to the 2D test (test_a_whole_2d_skin_reads_like_the_halved_pad)
    assert full.sides == 2 and quarter.sides == 1
    assert full.span == pytest.approx(quarter.span, rel=1e-3) == 4.0
    # the flat top's point is on the axis under the plate, not the mesh node nearest it (0.54 mm
    # off on these cells): s runs from -4 to 4
    assert (full.s.min(), full.s.max()) == (pytest.approx(-4.0, abs=1e-9), pytest.approx(4.0, abs=1e-9))


def test_a_sweep_of_a_skin_file_takes_its_thickness_not_the_papers(tmp_path):
    from tactileskin.cli._common import PHYSICS_KEYS, SCENE_KEYS
    from tactileskin.cli.sweep import scenes_from_options

    f = _gmsh_block(tmp_path / "skin.msh", dim=2, t=2.0)
    opts = {k: None for k in SCENE_KEYS + PHYSICS_KEYS}
    scenes = scenes_from_options({**opts, "skin_file": str(f), "indenter": "flat", "material": "silicone"})
    assert [s.thickness for s in scenes] == [pytest.approx(2.0)]  # not 1, 3, 5 (each refused)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_mesh_command_reports_a_skin_file(tmp_path, capsys, dim):
    from tactileskin.cli import main

    f = _gmsh_block(tmp_path / "skin.msh", dim=dim, t=2.0)
    assert main(["mesh", "--skin-file", str(f), "-i", "cylinder", "--indenter-radius", "2"]) == 0
    out = " ".join(capsys.readouterr().out.split())  # the table wraps at the terminal's width
    assert "as meshed in" in out and "Traceback" not in out
    area = 4.0 if dim == 2 else 16.0  # the block's bottom: w (x w)
    assert f"bonded boundary measure (mm^{dim - 1}) │ {area:g} │" in out


def test_a_scene_files_skin_file_implies_the_file_skin_as_the_option_does(tmp_path):
    from tactileskin import scenefile

    f = _gmsh_block(tmp_path / "skin.msh", dim=2, t=2.0)
    (tmp_path / "s.toml").write_text('skin_file = "skin.msh"\nindenter = "flat"\n')
    sf = scenefile.read(tmp_path / "s.toml")
    assert sf.fields["skin"] == "file" and sf.fields["skin_file"] == str(f)
    assert Scene.from_toml(tmp_path / "s.toml").skin == "file"


def _gmsh_polygon(path, pts, groups, h=0.5, order=1):
    """A 2D polygon skin; `groups`: {name: [edge indices]} (edge k runs from pts[k] to pts[k+1])."""
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        p = [occ.addPoint(x, y, 0) for x, y in pts]
        lines = [occ.addLine(p[k], p[(k + 1) % len(p)]) for k in range(len(p))]
        occ.addPlaneSurface([occ.addCurveLoop(lines)])
        occ.synchronize()
        for name, edges in groups.items():
            gmsh.model.addPhysicalGroup(1, [lines[k] for k in edges], name=name)
        gmsh.model.addPhysicalGroup(2, [1], name="skin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def _gmsh_rectangle(path, w=8.0, t=2.0, h=0.25):
    """A whole 2D block x in [-w/2, w/2], y in [0, t] (no symmetry group): bottom `bonded`,
    top `outer_surface`, the ends `sides`."""
    return _gmsh_polygon(path, [(-w / 2, 0.0), (w / 2, 0.0), (w / 2, t), (-w / 2, t)],
                         {"bonded": [0], "sides": [1, 3], "outer_surface": [2]}, h=h)


def test_a_whole_2d_skin_reads_like_the_halved_pad(tmp_path):
    """A 2D skin file without a symmetry group is solved whole; its profile runs across the
    centre. Its reaction (per mm of the half section), span and AUC are the halved pad's, and
    a force target presses both alike (before: the whole section's force, span and AUC, twice
    the pad's, so --force pressed the file skin half as deep). P2 meshes of h = 0.125 mm that
    differ (gmsh's rectangle, the pad mesher): reaction, span, AUC agree to 0.2 %, the peak to
    0.5 % (the bone fit at the centre line is one-sided on the halved model: -2.3 % at h = 0.25,
    converging as h^2), hence 1 %."""
    path = _gmsh_rectangle(tmp_path / "whole.msh", w=16.0, h=0.125)
    kw = dict(indenter="cylinder", indenter_radius=2.0, viscoelastic=False, mesh_size=0.125, refinement=1.0)
    whole_scene = Scene(skin="file", skin_file=str(path), depth=0.1, **kw)
    half_scene = Scene(skin="pad", pad_width=16.0, thickness=2.0, depth=0.1, **kw)
    whole, half = solve(whole_scene), solve(half_scene)
    assert whole.s.min() < -7.9 and half.s.min() > -1e-9      # two-sided against one-sided
    assert whole.sides == 2 and half.sides == 1
    assert whole.summary()["profile_sides"] == 2 and "profile_sides" not in half.summary()
    assert 1.0 < half.span < 4.0                               # the span ends inside the pad
    for name in ("reaction", "peak", "span", "auc"):
        assert getattr(whole, name) == pytest.approx(getattr(half, name), rel=0.01), name
    # force control on h = 0.25 (the reactions there agree to 3e-4)
    coarse = _gmsh_rectangle(tmp_path / "coarse.msh", w=16.0, h=0.25)
    target = 0.8 * half.reaction
    fw = solve(Scene(skin="file", skin_file=str(coarse), **{**kw, "mesh_size": 0.25}, force=target))
    fh = solve(half_scene.replace(depth=None, mesh_size=0.25, force=target))
    assert fw.loading["profile_travel_mm"] == pytest.approx(fh.loading["profile_travel_mm"], rel=0.01)


def test_a_binary_file_named_msh_is_one_error(tmp_path):
    """gmsh logs the file's bytes, which its Python API decodes as UTF-8: the one-line error
    became a traceback (seen from the command line, not under pytest's logging)."""
    import subprocess
    import sys

    path = tmp_path / "garbage.msh"
    path.write_bytes(np.random.default_rng(0).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    run = subprocess.run([sys.executable, "-m", "tactileskin", "solve", "--skin-file", str(path), "-i", "flat",
                          "--out", str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr and "skin_file" in run.stderr
    assert not (tmp_path / "o").exists()


def test_the_fingertips_own_msh_keeps_its_nail_edge_bonded(tmp_path):
    """`tactileskin mesh` names the fingertip's second bonded surface `nail_edge` (the dome's
    `bone_tip`); read back as a file skin it was a free surface: the same mesh at t = 3 read the
    flat plate's reaction 1.5 % and the peak 1.0 % low, status ok. Now held fixed: equal."""
    ft = Scene(skin="fingertip", thickness=3.0, indenter="flat", depth_fraction=0.05, viscoelastic=False,
               mesh_size=0.8, refinement=2.0)
    sm = build_mesh(ft)
    assert "nail_edge" in sm.boundaries
    user = Scene(skin="file", skin_file=str(sm.write(tmp_path / "ft.msh")), indenter="flat",
                 depth_fraction=0.05, viscoelastic=False)
    um = build_mesh(user)
    assert "nail_edge" in um.boundaries
    a, b = solve(ft, mesh=sm), solve(user, mesh=um)
    assert b.reaction == pytest.approx(a.reaction, rel=1e-9)
    assert b.peak == pytest.approx(a.peak, rel=1e-9)


def test_a_skin_placed_where_the_indenters_do_not_press_it_as_meant_is_refused(tmp_path):
    """The indenters come down (-y) centred on x = z = 0 and start at the contact surface's
    highest point. Each of these solved without a word or with a misleading one:
    - a block with its corner at the origin (x in [0, 16], no symmetry group): the cylinder
      pressed the free corner, reaction 0.0060 against 0.0163 N/mm, status ok;
    - the top sloping from y = 2 to 3 (highest at x = 8): depth 0.6 pressed the axis 0.1 deep
      (the gap first), status ok;
    - upside down (bonded group on top, contact group below): 'no contact'; with the rest of
      the boundary as contact: 'depth=0.1 is invalid; valid: (0, 0] mm';
    - a symmetric half on x <= 0: flagged 'edge peak'."""
    rect = [(-8, 0), (8, 0), (8, 2), (-8, 2)]
    kw = dict(indenter="cylinder", indenter_radius=2.0, depth=0.1)
    ok = _gmsh_polygon(tmp_path / "ok.msh", rect, {"bonded": [0], "outer_surface": [2]})
    assert Scene(skin="file", skin_file=str(ok), **kw).thickness == pytest.approx(2.0)
    corner = _gmsh_polygon(tmp_path / "corner.msh", [(x + 8, y) for x, y in rect], {"bonded": [0]})
    with pytest.raises(ParameterError, match=r"skin_file.*across the indenters' axis x = 0.*x in \[0, 16\]"):
        Scene(skin="file", skin_file=str(corner), **kw)
    sloped = _gmsh_polygon(tmp_path / "sloped.msh", [(-8, 0), (8, 0), (8, 3), (-8, 2)], {"bonded": [0]})
    with pytest.raises(ParameterError, match=r"skin_file.*highest on the indenters' axis.*x = 8 mm.*0.5 mm lower"):
        Scene(skin="file", skin_file=str(sloped), **{**kw, "depth": 0.6})
    upside = _gmsh_polygon(tmp_path / "upside.msh", rect, {"bonded": [2], "outer_surface": [0]})
    with pytest.raises(ParameterError, match=r"skin_outer.*contact surface on top.*upside down"):
        Scene(skin="file", skin_file=str(upside), **kw)
    upside_rest = _gmsh_polygon(tmp_path / "upside_rest.msh", rect, {"bonded": [2]})
    with pytest.raises(ParameterError, match=r"skin_bonded.*thickness 0.*upside down"):
        Scene(skin="file", skin_file=str(upside_rest), **kw)
    mirrored = _gmsh_polygon(tmp_path / "mirrored.msh", [(-8, 0), (0, 0), (0, 2), (-8, 2)],
                             {"bonded": [0], "symmetry": [1]})
    with pytest.raises(ParameterError, match=r"skin_file.*half model on x >= 0.*mirror it"):
        Scene(skin="file", skin_file=str(mirrored), **kw)
    half = _gmsh_polygon(tmp_path / "half.msh", [(0, 0), (8, 0), (8, 2), (0, 2)], {"bonded": [0], "symmetry": [3]})
    assert Scene(skin="file", skin_file=str(half), **kw).section().top == pytest.approx(2.0)


def _sloped_block(path, y_right):
    """A 4 x 4 mm STEP block on y = 0 whose top slopes from y = 2 (x = -2) to y_right (x = 2)."""
    import build123d as bd

    face = bd.Face(bd.Wire.make_polygon([(-2, 0, 0), (2, 0, 0), (2, y_right, 0), (-2, 2, 0)], close=True))
    bd.export_step(bd.Solid.extrude(face, (0, 0, 4)).translate((0, 0, -2)), str(path))
    return str(path)


def test_the_indenter_starts_at_first_touch_on_a_skin_higher_off_its_axis(tmp_path, caplog):
    """A STEP block whose top slopes from y = 2 (x = -2) to 2.04 (x = 2) is 0.02 mm higher at
    x = 2 than on the axis (within the allowed 2 % of t, so it is solved). Indenters start at
    the CAD point on the axis, y = 2.02: the flat plate started 0.02 mm inside the skin at x = 2
    (10 % of a 0.2 mm press). It now starts at first touch: no contact point overlaps it before
    the travel; a level block is not lifted."""
    import logging

    from tactileskin.fe import model_for_scene

    block = _sloped_block
    kw = dict(skin="file", indenter="flat", depth=0.2, viscoelastic=False, mesh_size=1.0, refinement=1.0)
    sc = Scene(skin_file=block(tmp_path / "sloped.step", 2.04), **kw)
    assert sc.section().top == pytest.approx(2.02, abs=1e-6)
    with caplog.at_level(logging.WARNING):
        model, _ = model_for_scene(sc)
    g0, _ = model.contact.indenter.gap(model.surface.X.reshape(-1, 3))
    assert -1e-3 * sc.indentation <= g0.min() <= 1e-9  # 1e-3 of the travel: the contact tolerance's cap
    # (0.0188 mm at the contact points, which lie inside the facets of the block's edge x = 2)
    assert re.search(r"stands 0\.01[89]\d* mm above its top point", caplog.text), caplog.text
    model, _ = model_for_scene(Scene(skin_file=block(tmp_path / "level.step", 2.0), **kw))
    assert model.contact.indenter.lowest_point == pytest.approx(2.0)  # not lifted
    assert np.min(model.contact.indenter.gap(model.surface.X.reshape(-1, 3))[0]) == pytest.approx(0.0, abs=1e-9)


def test_an_exported_deck_starts_the_indenter_at_first_touch_as_the_solver(tmp_path):
    """`export` writes what the solver solves: on the sloped block the solver starts the plate
    at first touch, but the deck placed it at the CAD point on the axis (y0 = 2.02), 0.02 mm
    inside the skin's nodes at x = 2 (10 % of a 0.2 mm press, as penetration at t = 0)."""
    from tactileskin.mesh.deck import deck_text

    sc = Scene(skin="file", skin_file=_sloped_block(tmp_path / "sloped.step", 2.04), indenter="flat", depth=0.2,
               viscoelastic=False, mesh_size=1.0, refinement=1.0)
    sm = build_mesh(sc)
    deck = deck_text(sc, sm, "calculix")
    y0 = float(re.search(r"lowest point at y0 = (\S+) mm", deck.text).group(1))
    top = sm.mesh.p[1, np.unique(sm.mesh.facets[:, sm.boundaries["outer_surface"]])].max()
    assert top == pytest.approx(2.04, abs=1e-6)
    assert top - 1e-3 * sc.indentation <= y0 <= top + 1e-9  # was 2.02


def test_an_upside_down_or_off_centre_step_is_refused(tmp_path):
    import build123d as bd

    box = bd.Box(8.0, 2.0, 8.0, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER))  # y in [-2, 0]
    bd.export_step(box, str(tmp_path / "up.step"))
    with pytest.raises(ParameterError, match=r"skin_bonded='normal:\+y'.*thickness 0"):
        Scene(skin="file", skin_file=str(tmp_path / "up.step"), skin_bonded="normal:+y")
    corner = bd.Box(8.0, 2.0, 8.0, align=(bd.Align.MIN, bd.Align.MIN, bd.Align.MIN))
    bd.export_step(corner, str(tmp_path / "corner.step"))
    with pytest.raises(ParameterError, match=r"skin_file.*axis x = 0.*x in \[0, 8\]"):
        Scene(skin="file", skin_file=str(tmp_path / "corner.step"))


def test_the_reports_run_settings_give_a_msh_skins_own_mesh_not_sizes_it_never_used(tmp_path):
    # a .msh is solved on its own mesh; the report stated the 2D default preset's 0.5 mm / 3
    # (refined 0.167 mm) for it, sizes the solve never used
    from tactileskin.report.markdown import run_settings

    f = _gmsh_block(tmp_path / "skin.msh", dim=2, t=2.0)
    text = "\n".join(run_settings([Scene(skin="file", skin_file=str(f), indenter="flat", mesh_size=0.5, refinement=3.0)]))
    assert "| 2D | flat | skin.msh's mesh | – | – | – | P2 |" in text
    assert "| 0.5 | 3 |" not in text


def test_a_step_skins_thickness_is_read_on_its_curved_bonded_face_not_on_the_chords(tmp_path):
    # a fingertip-like shell (a half tube, outer R 8, inner R 6: t = 2 mm) bonded on its inner
    # face: the coarse mesh's chords of that face read t = 2.06084 mm, and `-t 2` was refused
    import build123d as bd

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    shell = tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER))
    path = tmp_path / "shell.step"
    bd.export_step(shell, str(path))
    sc = Scene(skin="file", skin_file=str(path), skin_bonded="normal:-y:89.99")
    assert sc.thickness == pytest.approx(2.0, abs=1e-9)
    assert Scene(skin="file", skin_file=str(path), skin_bonded="normal:-y:89.99", thickness=2.0).thickness == 2.0
    # bonded on the flat strips at y = 0 alone (the default rule), the nearest bonded point is
    # their inner edge x = 6: t = hypot(6, 8), on an edge, not on the strips' plane (8)
    assert Scene(skin="file", skin_file=str(path)).thickness == pytest.approx(10.0, abs=1e-9)


def test_asking_2d_of_a_step_skin_says_how_to_get_a_2d_section(tmp_path, capsys):
    # "the file skin is 3D" named no way to a 2D solve of one's own skin: a 2D .msh of its section
    from tactileskin.cli import main

    path = _step_block(tmp_path / "block.step")
    assert main(["solve", "--skin-file", str(path), "--dim", "2", "-o", str(tmp_path / "out")]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "dim=2" in err and "2D .msh of its section" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def _arc_skin(path, order, R=20.0, half=4.0, top=2.0, n=10):
    """A 2D skin x in [-half, half] under an arc of radius R crowned at y = top, bonded on y = 0,
    meshed by gmsh at `order` with n - 1 elements on the arc (an odd count: no vertex on the axis)."""
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        yc = top - R
        ye = yc + np.sqrt(R * R - half * half)
        p = [occ.addPoint(x, y, 0) for x, y in ((-half, 0), (half, 0), (half, ye), (-half, ye))]
        c = occ.addPoint(0, yc, 0)
        lines = [occ.addLine(p[0], p[1]), occ.addLine(p[1], p[2]), occ.addCircleArc(p[2], c, p[3]),
                 occ.addLine(p[3], p[0])]
        occ.addPlaneSurface([occ.addCurveLoop(lines)])
        occ.synchronize()
        for name, k in (("bonded", [0]), ("outer_surface", [2]), ("sides", [1, 3])):
            gmsh.model.addPhysicalGroup(1, [lines[i] for i in k], name=name)
        gmsh.model.addPhysicalGroup(2, [1], name="skin")
        gmsh.model.mesh.setTransfiniteCurve(lines[2], n)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return str(path)


def test_a_p2_msh_whose_curved_top_has_no_vertex_on_the_axis_is_taken(tmp_path):
    """A 2D skin under an R 20 arc crowned at y = 2, meshed by gmsh at order 2 with 9 elements
    on the arc: no vertex on the axis, the middle element's mid-edge node at the crown. The
    placement check read the contact surface's vertices only (highest 1.995 mm) against the
    skin's nodes (2.0) and refused it as upside down. Its nodes now include the mid-edge ones:
    top and thickness 2.0 (the P1 mesh of the same arc is its chords: 1.995)."""
    p2 = Scene(skin="file", skin_file=_arc_skin(tmp_path / "p2.msh", 2), indenter="flat", depth=0.2)
    assert p2.section().top == pytest.approx(2.0, abs=1e-9) and p2.thickness == pytest.approx(2.0, abs=1e-9)
    p1 = Scene(skin="file", skin_file=_arc_skin(tmp_path / "p1.msh", 1), indenter="flat", depth=0.2)
    assert p1.thickness == pytest.approx(20.0 * np.cos(np.arcsin(4.0 / 20.0) / 9.0) - 18.0, abs=1e-9)  # the chord


def test_a_p2_msh_whose_crown_node_is_on_the_axis_is_not_highest_off_it(tmp_path):
    """An R 5 crown at t = 0.5 with 5 elements on the arc: its middle element's mid-edge node is
    the top, on the axis. The axis height was read on the straight chords, the sag (0.017 mm,
    3.4 % of t) under that node, and the skin refused as highest off the axis (at x = 9e-16); it
    is read on the curved facets, as the solver's surface and the top are: 0.5 there."""
    sc = Scene(skin="file", skin_file=_arc_skin(tmp_path / "p2.msh", 2, R=5.0, half=2.0, top=0.5, n=6),
               indenter="flat", depth=0.05)
    assert sc.thickness == pytest.approx(0.5, abs=1e-9) and sc.section().top == pytest.approx(0.5, abs=1e-9)
    # a skin really highest off its axis is refused all the same on a P2 mesh
    off = _gmsh_polygon(tmp_path / "tilt.msh", [(-4.0, 0.0), (4.0, 0.0), (4.0, 2.0), (-4.0, 1.5)],
                        {"bonded": [0], "sides": [1, 3], "outer_surface": [2]}, order=2)
    with pytest.raises(ParameterError, match="highest on the indenters' axis"):
        Scene(skin="file", skin_file=str(off), indenter="flat", depth=0.05)


@pytest.mark.parametrize("indenter", ["sphere", "cylinder"])
def test_an_indenter_on_a_curved_step_top_touches_at_once(tmp_path, indenter):
    """A 12 x 12 mm pad 2 mm thick with an R 3 cap 0.8 mm high on top (STEP): a sphere or
    cylinder starts on the cap's top, on the axis, and touches at once. The first-contact travel
    was read on the coarse mesh's contact nodes alone, none on the axis (the highest 0.11 mm
    under the top, 0.54 mm off it): 0.163 mm for the R 2.5 sphere, and a 0.1 mm indentation was
    refused as 'no contact'."""
    import build123d as bd

    from tactileskin.geometry.indenters import first_contact_travel, require_contact

    pad = bd.Box(12.0, 2.0, 12.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    cap = bd.Pos(0, -0.2, 0) * bd.Sphere(3.0) & bd.Pos(0, 2.0, 0) * bd.Box(
        20.0, 20.0, 20.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    path = tmp_path / "domepad.step"
    bd.export_step(pad + cap, str(path))
    scene = Scene(skin="file", skin_file=str(path), indenter=indenter, indenter_radius=2.5, depth=0.1)
    assert scene.thickness == pytest.approx(2.8, abs=1e-9)
    assert first_contact_travel(scene) == pytest.approx(0.0, abs=1e-9)
    require_contact(scene)  # no ParameterError


def test_a_skin_file_edited_while_it_is_read_is_not_kept_as_the_old_bytes(tmp_path, monkeypatch):
    """As an indenter file's surface: the skin file's analysis (its thickness among the rest)
    is memoised by the bytes hashed first, but the file was read again to analyse it, so an edit
    in between kept the other block's thickness under the first bytes' digest and key."""
    from tactileskin.mesh import skinfile
    from tactileskin.skins import file as skin_file

    f = _gmsh_block(tmp_path / "a.msh", dim=2, t=2.0)
    old = f.read_bytes()
    other = _gmsh_block(tmp_path / "b.msh", dim=2, t=3.0).read_bytes()
    real, calls = skinfile.load_msh, []

    def edited_meanwhile(path, *a, **k):
        if not calls:
            f.write_bytes(other)
        calls.append(path)
        return real(path, *a, **k)

    monkeypatch.setattr(skinfile, "load_msh", edited_meanwhile)
    skin_file._analyse.cache_clear()
    skin_file._coordinates.cache_clear()
    with pytest.raises(ParameterError, match="skin_file.*changed while it was read"):
        skin_file._analyse(*skin_file._key(type("S", (), {"skin_file": str(f), "skin_bonded": None,
                                                                 "skin_outer": None})()))
    f.write_bytes(old)
    assert Scene(skin="file", skin_file=str(f)).thickness == pytest.approx(2.0)  # not the 3 mm block's
    skin_file._analyse.cache_clear()
    skin_file._coordinates.cache_clear()
