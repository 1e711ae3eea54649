"""A box with its cards (a system) solved by CalculiX (Debian's ``calculix-ccx``) on the meshes pcbdyn made:
the box as :mod:`calculix` writes it (S4 plates, ribs as S4 strips), each card's shell sets as S4/S3 shells
with their own thickness and material (a region's non-structural mass folded into its density), its point
masses as MASS elements; a standoff's pad a rigid body about the standoff's centre, joined to the top of
the rib strip under it by three SPRING2 springs (x, y, z); a clamped guide's card nodes merged with the
wall's (the meshes conform there). CalculiX's springs act on translations only (ccx 2.20 takes rotational
DOFs in a *SPRING card silently and does nothing with them), so a guide with a rotational stiffness
k_rot has no CalculiX counterpart: the check takes clamped guides."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from calculix import _rows, box_deck, finish, run

from pcbdyn.fe import ShellProperty


def _card_lines(sm, pc, ids, eid) -> tuple:
    """(deck lines, next element number) of card ``pc``'s shells and point masses."""
    lines = []
    for name, es in sm.model.sets.items():
        if not name.startswith(f"cards.{pc.card.name}."):
            continue
        tag = name.replace(".", "_").replace("#", "_")
        if es.etype in ("quad4", "tri3"):
            p = es.prop
            assert isinstance(p, ShellProperty), name
            lines += [f"*ELEMENT, TYPE={'S4' if es.etype == 'quad4' else 'S3'}, ELSET={tag}", _rows(ids[es.conn], eid),
                      f"*SHELL SECTION, ELSET={tag}, MATERIAL={tag}", f"{p.t!r}", f"*MATERIAL, NAME={tag}",
                      "*ELASTIC", f"{p.E!r}, {p.nu!r}", "*DENSITY", f"{p.rho + p.nsm / p.t!r}"]
        elif es.etype == "mass":
            assert es.conn.shape[1] == 1 and not np.any(es.prop.inertia), name
            lines += [f"*ELEMENT, TYPE=MASS, ELSET={tag}", _rows(ids[es.conn], eid), f"*MASS, ELSET={tag}",
                      f"{es.prop.m!r}"]
        else:
            continue
        eid += len(es.conn)
    return lines, eid


def write_system_inp(path: Path, box, sm, n_modes: int) -> None:
    """An input deck of system model ``sm`` of ``box`` (guides clamped, standoffs springs on ribs)."""
    xyz, lines, held, columns, eid = box_deck(box, sm)
    n_mesh = len(sm.mesh.nodes)
    ids = np.zeros(sm.model.n_nodes, dtype=np.int64)  # system node -> deck node (0-based)
    ids[:n_mesh] = np.arange(n_mesh)
    parts, n = [xyz], len(xyz)
    tree = cKDTree(sm.mesh.nodes)
    for pc in sm.cards.values():
        ids[pc.nodes] = n + np.arange(pc.nodes.size)
        parts.append(sm.model.nodes[pc.nodes])
        n += pc.nodes.size
        for f in pc.card.board.fixtures:
            if f.type in ("wedge_lock", "clamped_edge"):
                assert f.type == "clamped_edge" or f.k_rot == "clamped", "CalculiX takes clamped guides only"
        d, near = tree.query(sm.model.nodes[pc.interface])
        edge = pc.interface[d < 1e-9]
        ids[edge] = near[d < 1e-9]  # merged with the wall's nodes
        card_lines, eid = _card_lines(sm, pc, ids, eid)
        lines += card_lines
        for hold in box.holds[pc.card.name]:
            f = hold.fixture
            if f.type != "standoff":
                continue
            centre = sm.point_nodes[f"cards.{pc.card.name}.fixtures.{f.name}"]
            local = pc.local.model.nodes
            pad = pc.first + np.flatnonzero(np.linalg.norm(local[:, :2] - np.asarray(f.at), axis=1) <= 0.5 * f.diameter + 1e-7)
            pad = pad[pad != centre]
            tag = f"PAD_{pc.card.name}_{f.name}"
            lines += [f"*NSET, NSET={tag}", "\n".join(", ".join(str(ids[k] + 1) for k in pad[i:i + 8])
                                                       for i in range(0, pad.size, 8)),
                      f"*RIGID BODY, NSET={tag}, REF NODE={ids[centre] + 1}"]
            h = int(tree.query(sm.model.nodes[centre])[1]) if hold.rib is None else None
            if hold.rib is not None:
                rib = box.rib(hold.rib)
                plate = box.plate(rib.plate)
                a, b = plate.point(*rib.start), plate.point(*rib.end)
                t = np.clip((sm.model.nodes[centre] - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
                foot = int(tree.query(a + t * (b - a))[1])
                h = int(columns[foot][-1])  # the rib strip's top node above the foot
            for k in (1, 2, 3):
                lines += [f"*ELEMENT, TYPE=SPRING2, ELSET=S_{pc.card.name}_{f.name}_{k}",
                          f"{eid}, {ids[centre] + 1}, {h + 1}", f"*SPRING,ELSET=S_{pc.card.name}_{f.name}_{k}",
                          f"{k},{k}", f"{float(f.k)!r}"]
                eid += 1
    finish(path, f"system {box.name}", np.vstack(parts), lines, held, n_modes)


def system_frequencies(folder: Path, box, sm, n_modes: int) -> np.ndarray:
    """CalculiX's first ``n_modes`` frequencies [Hz] of the system (one thread)."""
    write_system_inp(folder / "system.inp", box, sm, n_modes)
    return run(folder, "system", n_modes)
