"""A pcbdyn FE model rebuilt from the cards pyNastran read (``nastran_dump.py``'s JSON), following
the cards' Nastran meaning, not the writer's code:

- PSHELL: membrane T G1, bending (12I/T^3) T^3/12 G2, transverse shear (TS/T) T G3, where G is the
  plane-stress matrix of a MAT1 or the matrix of a MAT2 (its 2x2 G11, G12, G22 for MID3); mass
  rho1 T + NSM. Nastran's shells carry no rotary inertia; pcbdyn's Mindlin shell needs one and
  takes rho1 T^3 / 12.
- PBAR: I1 bends in the plane of x and v (about element z), K1/K2 shear factors (blank: rigid in
  shear); offsets WA = WB. pcbdyn's beam with rotary_inertia=False (no bending rotary inertia).
- CONM2 (CID 0, no offset): mass and inertia on the grid. CELAS2: a scalar spring between two
  components (or to ground). CBUSH: diagonal springs in its CORD2R. SPC1 fixes, MPC eliminates
  (first term dependent).
"""

from __future__ import annotations

import numpy as np

from pcbdyn.fe import BeamProperty, MassProperty, Model, SpringProperty


class MatrixShell:
    """A shell section given by its matrices (what a PSHELL describes)."""

    def __init__(self, A, D, S, m, inertia, t):
        self.A, self.D, self.S, self.m, self.inertia, self.t = A, D, S, m, inertia, t

    def membrane(self):
        return self.A

    def bending(self):
        return self.D

    def shear(self):
        return self.S

    def mass_per_area(self):
        return self.m

    def rotary_inertia_per_area(self):
        return self.inertia


def _plane_stress(deck, mid, shear=False):
    if str(mid) in deck["mat2"]:
        G = np.array(deck["mat2"][str(mid)]["G"], float)
        return G[:2, :2] if shear else G
    m = deck["mat1"][str(mid)]
    E, nu = m["E"], m["nu"]
    G = m["G"] if m["G"] else E / (2 * (1 + nu))
    if shear:
        return G * np.eye(2)
    c = E / (1 - nu**2)
    return np.array([[c, c * nu, 0], [c * nu, c, 0], [0, 0, G]])


def _rho(deck, mid):
    mats = deck["mat2"] if str(mid) in deck["mat2"] else deck["mat1"]
    return mats[str(mid)]["rho"] or 0.0


def shell_property(deck, pid) -> MatrixShell:
    p = deck["pshell"][str(pid)]
    t = p["t"]
    rho = _rho(deck, p["mid1"])
    A = t * _plane_stress(deck, p["mid1"])
    D = p["twelveIt3"] * t**3 / 12 * _plane_stress(deck, p["mid2"])
    S = p["tst"] * t * _plane_stress(deck, p["mid3"], shear=True)
    return MatrixShell(A, D, S, rho * t + p["nsm"], rho * t**3 / 12, t)


def beam_property(deck, pid, bar) -> BeamProperty:
    p = deck["pbar"][str(pid)]
    m = deck["mat1"][str(p["mid"])]
    assert bar["offt"] == "GGG" and np.allclose(bar["wa"], bar["wb"]), "offsets must be equal and global"
    return BeamProperty(m["E"], m["nu"], m["rho"], p["A"], p["i2"], p["i1"], p["j"], orientation=tuple(bar["x"]),
                        offset=tuple(bar["wa"]), shear_area_y=p["k1"] * p["A"] if p["k1"] else None,
                        shear_area_z=p["k2"] * p["A"] if p["k2"] else None, rotary_inertia=False)


def rebuild(deck: dict) -> Model:
    """The fe.Model of the deck; node i is grid id order i (the writer's node order)."""
    ids = sorted(int(n) for n in deck["grids"])
    index = {nid: i for i, nid in enumerate(ids)}
    model = Model(np.array([deck["grids"][str(n)] for n in ids]), free=True)
    groups: dict = {}

    def put(name, etype, cell, prop):
        groups.setdefault(name, (etype, prop, []))[2].append([index[n] for n in cell])

    for s in deck["shells"]:
        put(f"pshell{s['pid']}.{s['type']}", "quad4" if s["type"] == "CQUAD4" else "tri3", s["nodes"],
            shell_property(deck, s["pid"]))
    for i, b in enumerate(deck["bars"]):
        put(f"cbar{i}", "beam2", b["nodes"], beam_property(deck, b["pid"], b))
    for m in deck["conm2"]:
        assert m["cid"] == 0 and not any(m["x"]), "CONM2 with CID 0 and no offset"
        put(f"conm2.{m['eid']}", "mass", [m["node"]], MassProperty(m["mass"], np.array(m["inertia"])))
    for s in deck["springs"]:
        k = np.zeros(6)
        k[int(s["c1"]) - 1] = s["k"]
        nodes = [n for n in s["nodes"] if n]
        assert len(nodes) == 1 or s["c1"] == s["c2"], "CELAS2 between like components"
        put(f"celas2.{s['eid']}", "spring", nodes, SpringProperty(k=tuple(k)))
    for b in deck["bushes"]:
        R = np.array(deck["coords"][str(b["cid"])])
        T = np.kron(np.eye(2), R)
        k = T.T @ np.diag(deck["pbush"][str(b["pid"])]["k"]) @ T
        put(f"cbush.{b['eid']}", "spring", [n for n in b["nodes"] if n], SpringProperty(k=k))
    for name, (etype, prop, conn) in groups.items():
        model.add(name, etype, conn, prop)
    for s in deck["spc1"]:
        model.fix([index[n] for n in s["nodes"]], [int(c) - 1 for c in str(s["components"])])
    for m in deck["mpc"]:
        dofs = [6 * index[n] + int(c) - 1 for n, c in zip(m["nodes"], m["components"])]
        a = m["coefficients"]
        model.constrain(dofs[0], [(d, -c / a[0]) for d, c in zip(dofs[1:], a[1:])])
    return model
