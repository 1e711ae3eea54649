"""The box meshed by pcbdyn, solved by CalculiX (Debian's ``calculix-ccx``): an independent FE code on the
same geometry. Plates are S4 shells (CalculiX expands them to C3D8I bricks and joins plates meeting at an
angle through knots); each rib is a strip of S4 shells of the rib's width standing on the plate's nodes
along the rib line, from the plate's mid-surface to its top (t/2 + h), so that its bending stiffness
about the plate's mid-surface is the beam's (the integral of z^2 over 0..t/2+h less 0..t/2 is t^3/24,
a twelfth of a per cent here); clamped edges hold all six DOFs of their nodes, and a rib ending on one
is held there too (as a beam rib's end node is)."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

CCX = shutil.which("ccx")


def _rows(conn, first):
    return "\n".join(f"{first + k}, " + ", ".join(str(int(n) + 1) for n in c) for k, c in enumerate(conn))


def box_deck(box, pm, mesh_nodes: int | None = None) -> tuple:
    """(node xyz, deck lines of the elements and sections, held node numbers (1-based), rib strip nodes
    {plate node: its strip's column of node numbers (0-based)}, next element number) of the plates and
    ribs of ``box`` on the plate mesh of its built model ``pm``."""
    nodes = [pm.mesh.nodes]
    lines, eid, ends, columns = [], 1, [], {}
    for p in box.plates:
        conn = pm.mesh.cells[p.name]["quad4"]
        lines += [f"*ELEMENT, TYPE=S4, ELSET=P_{p.name}", _rows(conn, eid)]
        eid += len(conn)
        lines += [f"*SHELL SECTION, ELSET=P_{p.name}, MATERIAL=M_{p.name}", f"{p.thickness!r}"]
        lines += [f"*MATERIAL, NAME=M_{p.name}", "*ELASTIC", f"{p.material.E!r}, {p.material.nu!r}", "*DENSITY",
                  f"{p.material.rho!r}"]
    n = len(pm.mesh.nodes) if mesh_nodes is None else mesh_nodes
    for r in box.ribs:
        plate = box.plate(r.plate)
        a, b = plate.point(*r.start), plate.point(*r.end)
        chain = pm.mesh.chain(a, b, pm.mesh.plate_nodes(plate.name))
        rows = max(4, math.ceil((r.height + plate.thickness / 2) / (r.height / 4)))
        m = plate.normal * (1.0 if r.side == "+n" else -1.0)
        levels = (plate.thickness / 2 + r.height) * np.arange(1, rows + 1) / rows
        up = pm.mesh.nodes[chain][None] + levels[:, None, None] * m
        ids = np.vstack([chain[None], n + np.arange(up.shape[0] * up.shape[1]).reshape(up.shape[:2])])
        nodes.append(up.reshape(-1, 3))
        n += up.shape[0] * up.shape[1]
        ends += [(int(chain[0]), ids[1:, 0]), (int(chain[-1]), ids[1:, -1])]
        columns.update({int(c): ids[:, i] for i, c in enumerate(chain)})
        conn = np.array([[ids[k, i], ids[k, i + 1], ids[k + 1, i + 1], ids[k + 1, i]]
                         for k in range(rows) for i in range(len(chain) - 1)])
        lines += [f"*ELEMENT, TYPE=S4, ELSET=R_{r.name}", _rows(conn, eid)]
        eid += len(conn)
        lines += [f"*SHELL SECTION, ELSET=R_{r.name}, MATERIAL=MR_{r.name}", f"{r.width!r}",
                  f"*MATERIAL, NAME=MR_{r.name}", "*ELASTIC", f"{r.material.E!r}, {r.material.nu!r}", "*DENSITY",
                  f"{r.material.rho!r}"]
    edge = {int(k) for s in box.supports for k in pm.mesh.chain(*box.plate(s.plate).edge(s.edge),
                                                                pm.mesh.plate_nodes(s.plate))}
    held = sorted({k + 1 for k in edge} | {int(c) + 1 for foot, col in ends if foot in edge for c in col})
    return np.vstack(nodes), lines, held, columns, eid


def finish(path: Path, name: str, xyz, lines, held, n_modes: int) -> None:
    """Write the deck: nodes, ``lines``, the ``held`` nodes (1-based) clamped, a frequency step."""
    deck = ["*HEADING", f"pcbdyn {name}", "*NODE"]
    deck += [f"{i + 1}, {x:.17g}, {y:.17g}, {z:.17g}" for i, (x, y, z) in enumerate(xyz)]
    deck += lines + ["*NSET, NSET=HELD", "\n".join(", ".join(map(str, held[i:i + 8])) for i in range(0, len(held), 8))]
    deck += ["*BOUNDARY", "HELD, 1, 6", "*STEP", "*FREQUENCY", f"{n_modes}", "*END STEP"]
    path.write_text("\n".join(deck) + "\n")


def write_inp(path: Path, box, pm, n_modes: int) -> None:
    """An input deck of the base configuration of ``box`` on the plate mesh of its built model ``pm``."""
    xyz, lines, held, _, _ = box_deck(box, pm)
    finish(path, f"box {box.name}", xyz, lines, held, n_modes)


def run(folder: Path, stem: str, n_modes: int) -> np.ndarray:
    """CalculiX's first ``n_modes`` frequencies [Hz] of deck ``folder/stem.inp`` (one thread)."""
    subprocess.run([CCX, "-i", stem], cwd=folder, check=True, capture_output=True, timeout=1800,
                   env={"OMP_NUM_THREADS": "1", "CCX_NPROC_EQUATION_SOLVER": "1", "PATH": "/usr/bin:/bin"})
    text = (folder / f"{stem}.dat").read_text()
    table = text.split("E I G E N V A L U E   O U T P U T")[1]
    rows = re.findall(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", table, flags=re.M)
    return np.array([float(r[3]) for r in rows[:n_modes]])


def frequencies(folder: Path, box, pm, n_modes: int) -> np.ndarray:
    """CalculiX's first ``n_modes`` frequencies [Hz] of the box (one thread)."""
    write_inp(folder / "box.inp", box, pm, n_modes)
    return run(folder, "box", n_modes)
