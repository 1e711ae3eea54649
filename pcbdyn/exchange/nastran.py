"""An :class:`pcbdyn.fe.Model` as a Nastran SOL 103 deck (normal modes), card for card as pcbdyn
solves it, in SI units (m, kg, s, N, Pa).

- Nodes: GRID, id = node index + 1 (extra grids for bodies and beam ends follow).
- quad4 / tri3: CQUAD4 / CTRIA3 with a PSHELL per element set. An isotropic section is MAT1
  (E, nu, rho) with TS/T = the shear factor; any other (an equivalent laminate, a scaled region)
  is three MAT2 holding its membrane A / t, bending 12 D / t^3 and transverse shear S / t exactly.
  The density is chosen so that rho t^3 / 12 is pcbdyn's rotary inertia and NSM carries the rest
  of the mass; where that would need a negative NSM (copper outside a laminate), rho = m / t and
  the difference is listed in :attr:`Deck.notes`.
- beam2: CBAR with PBAR/MAT1, orientation vector and offsets (global, OFFT GGG), shear factors
  K1 = A_sy / A, K2 = A_sz / A (blank: Euler-Bernoulli). embedded_beam2: a CBAR between two extra
  grids at its end points, each end's six DOFs tied to the host shell's nodes by MPCs with the
  interpolation weights.
- mass: CONM2 with mass and inertia (global axes); a footprint mass is a CONM2 on an extra grid
  whose six DOFs follow the least-squares rigid motion of its footprint through MPCs (what
  pcbdyn's element does, an RBE3 written out as equations).
- spring: CELAS2 per non-zero diagonal term (a coupled 6x6 has no card here and is refused).
  edge_spring: its consistent stiffness per edge, grounded k L / 2 at each node and -k L / 6
  between them (CELAS2 in global components, or CBUSH/PBUSH in a CORD2R edge frame when the edge
  is not along an axis).
- fixed DOFs: SPC1; multi-point constraints: MPC (dependent DOF first), as pcbdyn eliminates
  them; EIGRL with the number of modes, the rigid-body ones of a free model included (and f_max);
  PARAM,COUPMASS,1 (consistent mass).

What a Nastran card cannot say (a beam's linear Timoshenko bending or rotary inertia, a
laminate's rotary inertia) is written as the nearest card and named in :attr:`Deck.notes`.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from ..atomic import atomic_path
from ..fe.elements.discrete import rigid_fit, spring_stiffness
from ..fe.elements.edge_spring import edge_frame
from ..fe.elements.shell_common import section
from ..fe.model import ModelError
from .bulk import card, comment

#: relative tolerance for "this section is isotropic" and "this frame is an axis permutation"
EXACT = 1e-10


@dataclass
class Deck:
    """A written deck: its text, the number of each card, the element sets with their property id
    and card type, extra grids, and notes on what the cards could not carry exactly."""

    text: str
    counts: Counter
    sets: list = field(default_factory=list)  # [{"set", "etype", "card", "pid", "elements"}]
    notes: list = field(default_factory=list)
    extra_grids: int = 0
    rigid_modes: int = 0  # rigid-body modes counted in EIGRL's ND besides the elastic modes asked for


class _Writer:
    def __init__(self, model):
        self.model = model
        self.lines: list[str] = []
        self.counts: Counter = Counter()
        self.ids: Counter = Counter()
        self.mpcs: list = []  # (grid, component, [(grid, component, coefficient), ...])
        self.notes: list = []
        self.frames: dict = {}
        self.next_grid = model.n_nodes + 1

    def add(self, name: str, fields) -> None:
        self.lines.append(card(name, fields))
        self.counts[name] += 1

    def new(self, kind: str) -> int:
        self.ids[kind] += 1
        return self.ids[kind]

    def grid(self, xyz) -> int:
        gid = self.next_grid
        self.next_grid += 1
        self.add("GRID", [gid, None, *map(float, xyz)])
        return gid

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)

    def frame(self, R: np.ndarray) -> int:
        """A CORD2R whose axes are the rows of R (shared by equal frames)."""
        key = tuple(np.round(R, 12).ravel())
        if key not in self.frames:
            cid = self.new("coord")
            self.add("CORD2R", [cid, None, 0.0, 0.0, 0.0, *map(float, R[2]), *map(float, R[0])])
            self.frames[key] = cid
        return self.frames[key]


# ------------------------------------------------------------------------------------ properties


def _isotropic(sec, t: float):
    """(E, nu, shear factor) when the section is a homogeneous isotropic plate of thickness t."""
    A, D, S = sec.A, sec.D, sec.S
    nu = A[0, 1] / A[0, 0]
    E = A[0, 0] * (1.0 - nu**2) / t
    G = E / (2.0 * (1.0 + nu))
    k = S[0, 0] / (G * t)
    iso = E * t / (1.0 - nu**2) * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
    same = (np.allclose(A, iso, rtol=EXACT, atol=EXACT * abs(A).max())
            and np.allclose(D, A * t**2 / 12.0, rtol=EXACT, atol=EXACT * abs(D).max())
            and np.allclose(S, k * G * t * np.eye(2), rtol=EXACT, atol=EXACT * abs(S).max()))
    return (E, nu, k) if same else None


def _shell_property(w: _Writer, prop, name: str) -> int:
    sec = section(prop)
    t = float(prop.t)
    rho = 12.0 * sec.I / t**3
    nsm = sec.m - rho * t
    if nsm < -EXACT * sec.m:
        rho, nsm = sec.m / t, 0.0
        w.note(f"{name}: rotary inertia {sec.I:.4g} kg per area has no PSHELL field; the deck's rho t^3/12 "
               f"is {rho * t**3 / 12.0:.4g} kg (Nastran's shells leave rotary inertia out anyway)")
    nsm = max(nsm, 0.0)
    pid = w.new("prop")
    iso = _isotropic(sec, t)
    if iso is not None:
        E, nu, k = iso
        mid = w.new("mat")
        w.add("MAT1", [mid, E, None, nu, rho])
        w.add("PSHELL", [pid, mid, t, mid, 1.0, mid, k, nsm])
        return pid
    m1, m2, m3 = (w.new("mat") for _ in range(3))
    for mid, G, r in ((m1, sec.A / t, rho), (m2, 12.0 * sec.D / t**3, None)):
        w.add("MAT2", [mid, G[0, 0], G[0, 1], G[0, 2], G[1, 1], G[1, 2], G[2, 2], r])
    Gs = sec.S / t
    w.add("MAT2", [m3, Gs[0, 0], Gs[0, 1], None, Gs[1, 1]])
    w.add("PSHELL", [pid, m1, t, m2, 1.0, m3, 1.0, nsm])
    return pid


def _beam_property(w: _Writer, prop, name: str) -> int:
    if prop.rotary_inertia:
        w.note(f"{name}: the section's rotary inertia in bending (rho I) has no PBAR field; left out")
    if prop.linear_bending:
        w.note(f"{name}: pcbdyn bends this beam as a linear Timoshenko beam (tied to a Mindlin shell); "
               "CBAR is the cubic beam, stiffer on a coarse mesh")
    mid, pid = w.new("mat"), w.new("prop")
    w.add("MAT1", [mid, prop.E, None, prop.nu, prop.rho])
    k1 = prop.shear_area_y / prop.A if prop.shear_area_y else None
    k2 = prop.shear_area_z / prop.A if prop.shear_area_z else None
    w.add("PBAR", [pid, mid, prop.A, prop.Iz, prop.Iy, prop.J, None, None] + [None] * 8 + [k1, k2])
    return pid


# -------------------------------------------------------------------------------------- elements


def _shells(w: _Writer, es) -> tuple:
    pid = _shell_property(w, es.prop, es.name)
    name = "CQUAD4" if es.etype == "quad4" else "CTRIA3"
    for cell in es.conn:
        w.add(name, [w.new("elem"), pid, *(int(n) + 1 for n in cell)])
    return name, pid


def _cbar(w: _Writer, pid: int, ga: int, gb: int, prop) -> None:
    off = [float(v) for v in prop.offset]
    w.add("CBAR", [w.new("elem"), pid, ga, gb, *map(float, prop.orientation), None, None, None, *off, *off])


def _beams(w: _Writer, es) -> tuple:
    pid = _beam_property(w, es.prop, es.name)
    for a, b in es.conn:
        _cbar(w, pid, int(a) + 1, int(b) + 1, es.prop)
    return "CBAR", pid


def _terms(dof_nodes, dof_components, coefficients) -> list:
    """MPC terms [(grid, component, c)]: repeated (node, component) pairs summed, zeros dropped."""
    acc: dict = {}
    for n, comp, c in zip(dof_nodes, dof_components, coefficients):
        key = (int(n) + 1, int(comp))
        acc[key] = acc.get(key, 0.0) + float(c)
    scale = max((abs(c) for c in acc.values()), default=0.0)
    return [(g, comp, c) for (g, comp), c in acc.items() if abs(c) > 1e-14 * scale]


def _embedded_beams(w: _Writer, es) -> tuple:
    beam = es.prop.beam
    pid = _beam_property(w, beam, es.name)
    for cell, weights in zip(es.conn, np.asarray(es.prop.weights, float)):
        ends = weights @ w.model.nodes[cell]
        ga, gb = w.grid(ends[0]), w.grid(ends[1])
        _cbar(w, pid, ga, gb, beam)
        for gid, wt in ((ga, weights[0]), (gb, weights[1])):
            for comp in range(1, 7):
                w.mpcs.append((gid, comp, _terms(cell, np.full(cell.size, comp), wt)))
    return "CBAR", pid


def _conm2(w: _Writer, gid: int, prop) -> None:
    J = prop.inertia_matrix()
    w.add("CONM2", [w.new("elem"), gid, 0, float(prop.m), None, None, None, None,
                    J[0, 0], -J[1, 0], J[1, 1], -J[2, 0], -J[2, 1], J[2, 2]])


def _masses(w: _Writer, es) -> tuple:
    if es.conn.shape[1] == 1:
        for (n,) in es.conn:
            _conm2(w, int(n) + 1, es.prop)
        return "CONM2", None
    body, G = rigid_fit(w.model.nodes[es.conn], es.prop)
    for cell, xyz, g in zip(es.conn, body, G):
        gid = w.grid(xyz)
        _conm2(w, gid, es.prop)
        for row in range(6):
            w.mpcs.append((gid, row + 1, _terms(np.repeat(cell, 3), np.tile([1, 2, 3], cell.size), g[row])))
    return "CONM2", None


def _spring6(w: _Writer, ga: int, gb, k, R) -> str:
    """Six springs ``k`` (diagonal, in the frame whose axes are the rows of R) from grid ga to gb
    (None: ground): CELAS2 per non-zero term when R only permutes the global axes, else a CBUSH
    in a CORD2R of that frame. Returns the card used."""
    axes = np.argmax(np.abs(R), axis=1)
    if np.allclose(np.abs(R), np.eye(3)[axes], rtol=0.0, atol=EXACT):
        for i in np.flatnonzero(np.asarray(k) != 0.0):
            comp = int(axes[i % 3] + 1 + 3 * (i // 3))
            w.add("CELAS2", [w.new("elem"), float(k[i]), ga, comp, gb, comp if gb else None])
        return "CELAS2"
    cid, pid = w.frame(R), w.new("prop")
    w.add("PBUSH", [pid, "K", *map(float, k)])
    w.add("CBUSH", [w.new("elem"), pid, ga, gb, None, None, None, cid])
    return "CBUSH"


def _springs(w: _Writer, es) -> tuple:
    k = spring_stiffness(es.prop.k)
    if np.count_nonzero(k - np.diag(np.diag(k))):
        raise ModelError(f"element set '{es.name}': a coupled 6x6 spring has no Nastran card here (CELAS/CBUSH "
                         "are diagonal); give its six diagonal terms, or write that set as DMIG by hand")
    used = "CELAS2"
    for cell in es.conn:
        ids = [int(n) + 1 for n in cell]
        used = _spring6(w, ids[0], ids[1] if len(ids) > 1 else None, np.diag(k), np.eye(3))
    return used, None


def _edge_springs(w: _Writer, es) -> tuple:
    L, R = edge_frame(w.model.nodes[es.conn], es.prop.normal)
    k = np.asarray(es.prop.k, dtype=float)
    used = "CELAS2"
    for (a, b), length, frame in zip(es.conn, L, R):
        for ga, gb, share in ((a, None, 0.5), (b, None, 0.5), (a, b, -1.0 / 6.0)):
            used = _spring6(w, int(ga) + 1, None if gb is None else int(gb) + 1, share * length * k, frame)
    return used, None


WRITERS = {"quad4": _shells, "tri3": _shells, "beam2": _beams, "embedded_beam2": _embedded_beams,
           "mass": _masses, "spring": _springs, "edge_spring": _edge_springs}


def _constraints(w: _Writer) -> None:
    """SPC1 for the fixed DOFs (grouped by component set), MPC for pcbdyn's constraints and the
    ties written above. A constraint whose dependent DOF is fixed is left out: pcbdyn holds it."""
    model = w.model
    fixed = np.zeros(model.n_dof, dtype=bool)
    if model.fixed:
        fixed[np.fromiter(model.fixed, dtype=np.int64)] = True
    held = fixed.reshape(-1, 6)
    groups: dict = {}
    for node in np.flatnonzero(held.any(axis=1)):
        comps = "".join(str(c + 1) for c in np.flatnonzero(held[node]))
        groups.setdefault(comps, []).append(int(node) + 1)
    for comps, grids in groups.items():
        for start in range(0, len(grids), 5000):
            w.add("SPC1", [1, comps, *grids[start:start + 5000]])
    own = [(s // 6 + 1, s % 6 + 1, [(m // 6 + 1, m % 6 + 1, c) for m, c in terms])
           for s, terms in model.mpcs if not fixed[s]]
    for gid, comp, terms in own + w.mpcs:
        fields = [1, gid, comp, 1.0]  # line 1: the dependent DOF and one term; then two terms a line
        for k, (g, c, a) in enumerate(terms):
            if k % 2 == 1:
                fields += [None, None]
            fields += [g, c, -a]
        w.add("MPC", fields)


def nastran_deck(model, n_modes: int, f_max: float | None = None, title: str = "pcbdyn model",
                 header: str = "") -> Deck:
    """The SOL 103 deck of ``model`` asking for ``n_modes`` elastic modes (below ``f_max`` [Hz] if given; EIGRL's
    ND adds the rigid-body modes of a free model);
    ``header``: comment lines put first (where the model comes from)."""
    w = _Writer(model)
    for i, xyz in enumerate(model.nodes):
        w.add("GRID", [i + 1, None, *map(float, xyz)])
    sets = []
    for es in model.sets.values():
        if es.etype not in WRITERS:
            raise ModelError(f"element set '{es.name}': element type '{es.etype}' has no Nastran writer")
        w.lines.append(comment(f"element set '{es.name}' ({es.etype}, {len(es.conn)} cells)"))
        used, pid = WRITERS[es.etype](w, es)
        sets.append({"set": es.name, "etype": es.etype, "card": used, "pid": pid, "elements": int(len(es.conn))})
    _constraints(w)
    rigid = _rigid_modes(model)
    w.add("EIGRL", [1, None, None if f_max is None else float(f_max), int(n_modes) + rigid])
    control = ["SOL 103", "CEND", f"TITLE = {title}"[:72], "ECHO = NONE", "METHOD = 1"]
    control += ["SPC = 1"] if w.counts["SPC1"] else []
    control += ["MPC = 1"] if w.counts["MPC"] else []
    control += ["DISPLACEMENT(PLOT) = ALL", "BEGIN BULK", "PARAM,COUPMASS,1", "PARAM,GRDPNT,0", "PARAM,AUTOSPC,YES"]
    notes = comment("Notes: what the cards cannot carry exactly\n" + "\n".join(w.notes)) if w.notes else ""
    head = comment("\n".join(filter(None, [header, "Units: SI (m, kg, s, N, Pa). Written by pcbdyn from its FE "
                                                 "model as it is solved."])))
    text = head + notes + "\n".join(control) + "\n" + "".join(w.lines) + "ENDDATA\n"
    return Deck(text, w.counts, sets, w.notes, w.next_grid - 1 - model.n_nodes, rigid)


def _rigid_modes(model) -> int:
    """The rigid-body modes of a free model: Nastran's EIGRL counts them in ND, so that asking for n modes
    of a free card gave n - 6 elastic ones."""
    from ..fe.modal import solve_modes

    return solve_modes(model, n_modes=1).n_rigid if model.free else 0


def write_nastran(path, model, n_modes: int, f_max: float | None = None, title: str = "pcbdyn model",
                  header: str = "") -> Deck:
    """Write :func:`nastran_deck` to ``path`` atomically and return it."""
    deck = nastran_deck(model, n_modes, f_max, title, header)
    with atomic_path(path) as tmp:
        tmp.write_text(deck.text)
    return deck
