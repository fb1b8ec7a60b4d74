"""A 3D scene as a CalculiX input deck: C3D10 skin, meshed rigid indenter, penalty contact.

`deck_text_3d(scene, skinmesh, ...)` writes what the 3D solver solves (fe.model_for_scene):
- the skin's P2 tetrahedra as C3D10 (scikit-fem's edge order (0,1) (1,2) (0,2) (0,3) (1,3)
  (2,3) is C3D10's mid-node order 5-10; gmsh's tetra10 swaps the last two, which
  mesh._gmsh undoes on import; cells with node 4 on the negative side of face 1-2-3 are
  flipped, deck.abaqus_cells), one *NSET and one element-face *SURFACE per named boundary;
- the material as *HYPERFOAM (instantaneous; ccx has no Prony series);
- supports: the skin's bonded boundaries fixed in x, y, z (fingertip: bone_interface and
  nail_edge), u_x = 0 on the symmetry plane x = 0 of a half model, u_z = 0 on end_back when
  the mesh is z-symmetric (the plane z = 0); end_front (and a non-symmetric end_back) free;
- the indenter (flat, braille, sphere, cylinder, curved): its working face triangulated on
  the kind's exact surface (mesh.indenter3d; a sphere or cylinder up to twice the travel
  above its lowest point, a flat flange beyond, where the skin cannot reach); a file
  indenter: its own triangles that reach below twice the travel over the skin (its face must
  point down there: indenter3d.file_face; the facets are the solver's surface too); thickened
  into C3D6 wedges whose nodes are all moved by the travel (a rigid translation without
  *RIGID BODY, as the 2D CalculiX deck does); the face extends 1 mm past the skin on every
  side, like the solver's unbounded analytic indenter;
- frictionless surface-to-surface contact, skin outer surface slave, indenter face master,
  linear penalty `penalty` MPa/mm (default 40 K0 / h_fine: at 2D's 10 K0 / h ccx let the t = 1 mm
  plate penetrate 3.5 % of the travel and read 5.6 % low in bone pressure; 40 and 160 converged
  on every 3D case run, benchmarks/results/calculix_compare3d.md);
- one NLGEOM *STATIC step from zero to the full travel over the scene's ramp time; under
  force control (a scene's `force`, no [[loading]]) two: the indenter's wedge nodes keep x and
  z fixed and their y tied to its first node, indenter_ref (*EQUATION: a rigid translation),
  which the first step presses PRE_TRAVEL x the expected travel (a free indenter at first touch
  has no stiffness in y: the penalty acts on penetration only, so ccx's first increment would
  be singular); the second frees it (*BOUNDARY, OP=NEW) and ramps the force on it (*CLOAD,
  the modelled part's share) from zero over the ramp time. On the R 2.5 sphere on the t = 1
  pad at 0.3 N ccx travelled 0.1966 mm, tactileskin 0.1957 mm on the same mesh (displacement
  formulation; +0.44 %: ccx's penetration and facets), benchmarks/results/calculix_compare3d.md.

Forces in the .dat totals are those of the modelled part (a quarter for a flat plate or a
symmetric Braille cell): `info["force_factor"]` gives the whole indenter's, as
Result.reaction reports it. Only the CalculiX dialect: an Abaqus 3D deck would need
R3D3 elements on a *RIGID BODY, which nothing here can run to check.
"""

from __future__ import annotations

import io
import logging

import numpy as np

from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

WEDGE_HEIGHT = 0.5  # mm: thickness of the indenter's wedge layer (its nodes all prescribed or tied)
PENALTY_FACTOR = 40.0  # default contact slope in K0 / h_fine (module docstring)
# force control: the pre-step's travel, a fraction of the expected travel (module docstring). At 1 %
# (0.002 mm on the t = 1 pad) the contact it left could not carry the first force increment: ccx 2.20
# stopped on a singular matrix in step 2 for the R 2.5 sphere at 0.3 N on the 1.6 / 4 mesh (also an
# icosphere STL there, and the 1.6 / 8 deck under OMP_NUM_THREADS=2); at 5 % all three reach the force,
# the 1.6 / 8 travel 0.19662 mm (0.19657 at 1 %, one thread). Elastic and frictionless: the path does not matter
PRE_TRAVEL = 0.05


def footprint(skinmesh, margin: float = 1.0) -> tuple[float, float, float, float]:
    """(xmin, xmax, zmin, zmax) of the indenter face: the skin's extent plus `margin` mm."""
    X = np.asarray(skinmesh.mesh.doflocs, float)
    return (float(X[0].min()) - margin, float(X[0].max()) + margin,
            float(X[2].min()) - margin, float(X[2].max()) + margin)


def deck_text_3d(scene, skinmesh, *, penalty: float | None = None, increments: int = 20,
                 face_size: float | None = None, cap_size: float | None = None,
                 viscoelastic: bool | None = None):
    """The CalculiX deck of a 3D scene on its mesh (a deck.Deck). face_size: indenter facet
    size away from the Braille caps or a sphere's or cylinder's cap (default the skin's coarse
    size: a plane is exact at any size); cap_size: on the caps (default indenter3d's);
    penalty (MPa/mm): default PENALTY_FACTOR K0 / h_fine; increments: as deck.deck_text."""
    from tactileskin.geometry.indenters import at_first_touch, indenter_for_scene
    from tactileskin.materials import get_material
    from tactileskin.mesh.deck import (Deck, _name, _num, abaqus_cells, contact_nodes, indenter_mesh_lines,
                                        material_lines, skin_mesh_lines)
    from tactileskin.mesh.indenter3d import cap_rise, file_face, indenter_face, max_chord_error, wedge_cells

    if skinmesh.dim != 3:
        raise ParameterError("mesh", f"{skinmesh.dim}D", "a 3D skin mesh for a 3D deck")
    mat = get_material(scene.material)
    visco = scene.viscoelastic if viscoelastic is None else bool(viscoelastic)
    ind = at_first_touch(scene, indenter_for_scene(scene), contact_nodes(skinmesh))  # as fe.model_for_scene
    etype, pts, cells = abaqus_cells(skinmesh)
    n_nodes, n_cells = len(pts), len(cells)
    T, depth = scene.duration, scene.indentation
    h_fine = float(skinmesh.sizes.get("fine", scene.mesh_size / scene.refinement))
    h_face = float(face_size if face_size is not None else skinmesh.sizes.get("coarse", scene.mesh_size))
    hf = mat.hyperfoam
    if penalty is None:
        penalty = PENALTY_FACTOR * max(hf.K0, hf.mu0) / h_fine
    if not (isinstance(penalty, (int, float)) and np.isfinite(penalty) and penalty > 0):
        raise ParameterError("penalty", penalty, "a positive contact stiffness (MPa/mm)")
    if ind.kind == "file":  # its own triangles: the surface the solver's gap measures, exact
        face, chord = file_face(ind, footprint(skinmesh), scene.reach), 0.0
    else:
        face = indenter_face(ind, footprint(skinmesh), h_face, cap_size, reach=scene.reach)
        chord = max_chord_error(face, ind)
    ipts, icells = wedge_cells(face, WEDGE_HEIGHT)
    halved, zsym = bool(skinmesh.halved), bool(getattr(skinmesh, "z_symmetric", False))

    fh = io.StringIO()
    w = fh.write
    w("*HEADING\n")
    w(f"tactileskin {scene.label()}: 3D, units mm s N MPa (calculix)\n")
    w("**\n** Skin: C3D10; then the indenter's wedge nodes\n*NODE\n")
    skin_mesh_lines(fh, skinmesh, np.concatenate([pts, ipts]), cells, etype, 3)
    w(material_lines(mat, viscoelastic=False, dialect="calculix"))
    w(f"*SOLID SECTION, ELSET=skin, MATERIAL={_name(mat.name)}\n")

    ref, n_ind = n_nodes + 1, len(ipts)
    moves = ("moves by -" + _num(depth) + " mm" if scene.force is None else "pushed by " + _num(scene.force) + " N")
    w("**\n** Indenter (" + ind.kind + "): lowest point at y0 = " + _num(ind.y0) + " mm, " + moves + " over "
      + _num(T) + " s; C3D6 wedges, face S1 on the working face,\n"
      + ("** all nodes prescribed (a rigid translation)\n" if scene.force is None else
         "** x and z fixed, y tied to indenter_ref's (*EQUATION: a rigid translation)\n"))
    if face.caps:
        w("** the face is the exact surface up to " + _num(cap_rise(ind, scene.reach)) + " mm above its lowest point "
          "(at most twice the travel), a flat flange beyond\n")
    indenter_mesh_lines(fh, ref, n_ind, icells, n_cells, "C3D6")
    if scene.force is not None:  # one rigid translation: every node's y follows the first's
        w(f"*NSET, NSET=indenter_ref\n{ref}\n*EQUATION\n")
        for k in range(ref + 1, ref + n_ind):
            w(f"2\n{k}, 2, 1., {ref}, 2, -1.\n")
    w("*MATERIAL, NAME=indenter_rigid\n*ELASTIC\n1e6, 0.3\n")
    w("*SOLID SECTION, ELSET=indenter, MATERIAL=indenter_rigid\n")

    w("**\n** Contact: frictionless (no *FRICTION), linear penalty\n")
    w("*SURFACE INTERACTION, NAME=frictionless\n")
    w(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{_num(penalty)}\n")
    w("*CONTACT PAIR, INTERACTION=frictionless, TYPE=SURFACE TO SURFACE\n")
    w("outer_surface_faces, indenter_face\n")
    w(f"*AMPLITUDE, NAME=travel\n0., 0., {_num(T)}, 1.\n")

    fixed = [b for b in scene.skin_kind.fixed_boundaries if b in skinmesh.boundaries]
    w("**\n** Supports: " + ", ".join(fixed) + " fixed" + ("; symmetry plane x = 0" if halved else "")
      + ("; end_back is the symmetry plane z = 0" if zsym else "") + "\n")
    supports = ("".join(f"{b}, 1, 3\n" for b in fixed) + ("symmetry, 1, 1\n" if halved else "")
                + ("end_back, 3, 3\n" if zsym else "") + "indenter_nodes, 1, 1\nindenter_nodes, 3, 3\n")
    w("*BOUNDARY\n" + supports)

    dt0 = T / increments
    factor = (2.0 if halved else 1.0) * (2.0 if zsym else 1.0)
    force, pre = scene.force, None
    if force is None:
        w(f"**\n** indentation {_num(depth)} mm at {_num(scene.rate)} mm/s\n")
        w("*STEP, NLGEOM, INC=10000\n")
        w(f"*STATIC\n{_num(dt0)}, {_num(T)}, {_num(T * 1e-6)}, {_num(T / 10)}\n")
        w("*BOUNDARY, AMPLITUDE=travel\n")
        w(f"indenter_nodes, 2, 2, {_num(-depth)}\n")
        _outputs(w)
        w("*END STEP\n")
    else:
        # force control: a free indenter at first touch has no stiffness in y (the penalty acts on
        # penetration only), so a first step presses it PRE_TRAVEL x the expected travel under
        # displacement control, then the second frees it and ramps the force from zero (the
        # pre-step's reaction, ~1 % of a Hertzian force, is let go at once)
        pre = PRE_TRAVEL * depth
        t_pre = pre / scene.rate
        w(f"**\n** pre-step: {_num(pre)} mm under displacement control, then force control: {_num(force)} N on "
          f"the whole indenter ({_num(force / factor)} N on the modelled part) over {_num(T)} s\n")
        w(f"*AMPLITUDE, NAME=pre\n0., 0., {_num(t_pre)}, 1.\n")
        w("*STEP, NLGEOM, INC=10000\n")
        w(f"*STATIC\n{_num(t_pre / 2)}, {_num(t_pre)}, {_num(t_pre * 1e-6)}, {_num(t_pre)}\n")
        w("*BOUNDARY, AMPLITUDE=pre\n")
        w(f"indenter_ref, 2, 2, {_num(-pre)}\n")
        w("*END STEP\n")
        w("*STEP, NLGEOM, INC=10000\n")
        w(f"*STATIC\n{_num(dt0)}, {_num(T)}, {_num(T * 1e-6)}, {_num(T / 10)}\n")
        w("*BOUNDARY, OP=NEW\n" + supports)  # all but indenter_ref's y
        w("*CLOAD, AMPLITUDE=travel\n")
        w(f"indenter_ref, 2, {_num(-force / factor)}\n")
        _outputs(w)
        w("*NODE PRINT, NSET=indenter_ref\nU\n")
        w("*END STEP\n")
    if visco and mat.prony.n_terms:
        log.warning("CalculiX has no Prony viscoelasticity: the deck uses the instantaneous hyperfoam alone")
    info = {"indenter_nodes": n_ind, "indenter_cells": len(icells), "penalty_mpa_per_mm": float(penalty),
            "viscoelastic": False, "time_s": T, "depth_mm": None if force is not None else depth,
            "force_n": force, "pre_travel_mm": pre, "force_factor": factor,
            "face_size_mm": h_face, "face_chord_error_mm": chord}
    return Deck(fh.getvalue(), "calculix", n_nodes, n_cells, etype, info)


def _outputs(w) -> None:
    w("*NODE FILE\nU, RF\n*EL FILE\nS, E\n*CONTACT FILE\nCDIS, CSTR\n")
    w("*NODE PRINT, NSET=bone_interface, TOTALS=ONLY\nRF\n")
    w("*NODE PRINT, NSET=indenter_nodes, TOTALS=ONLY\nRF\n")
