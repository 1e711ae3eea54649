"""Read a Nastran deck with pyNastran and print its cards as JSON (run by the pyNastran venv).

pyNastran pins numpy<2, so it lives in its own virtual environment (.venv-nastran, made by
scripts/setup.sh); the tests call this script there and rebuild a pcbdyn model from what it
prints. Only pyNastran's reading of the deck is used: card fields as pyNastran parsed them, its
card counts and its mass properties.

usage: python nastran_dump.py model.bdf
"""

import json
import sys

from pyNastran.bdf.bdf import read_bdf
from pyNastran.bdf.mesh_utils.mass_properties import mass_properties


def _f(v):
    return None if v is None else float(v)


def dump(path: str) -> dict:
    model = read_bdf(path, xref=True, punch=False, debug=None)
    mass, cg, inertia = mass_properties(model)
    out = {
        "card_count": {k: int(v) for k, v in model.card_count.items()},
        "mass": float(mass), "cg": [float(v) for v in cg],
        "grids": {nid: [float(v) for v in n.get_position()] for nid, n in model.nodes.items()},
        "shells": [], "bars": [], "springs": [], "bushes": [], "conm2": [],
        "pshell": {}, "pbar": {}, "pbush": {}, "mat1": {}, "mat2": {}, "coords": {},
        "spc1": [], "mpc": [],
        "eigrl": {sid: {"v1": _f(m.v1), "v2": _f(m.v2), "nd": m.nd} for sid, m in model.methods.items()},
    }
    for eid, e in model.elements.items():
        if e.type in ("CQUAD4", "CTRIA3"):
            out["shells"].append({"type": e.type, "eid": eid, "pid": e.pid, "nodes": e.node_ids})
        elif e.type == "CBAR":
            out["bars"].append({"eid": eid, "pid": e.pid, "nodes": e.node_ids, "x": [_f(v) for v in e.x],
                                "offt": e.offt, "wa": [_f(v) for v in e.wa], "wb": [_f(v) for v in e.wb]})
        elif e.type == "CELAS2":
            out["springs"].append({"eid": eid, "k": e.k, "nodes": list(e.nodes), "c1": e.c1, "c2": e.c2})
        elif e.type == "CBUSH":
            out["bushes"].append({"eid": eid, "pid": e.pid, "nodes": [e.Ga(), e.Gb()], "cid": e.Cid()})
        else:
            raise SystemExit(f"{path}: element {e.type} is not rebuilt by the tests")
    for eid, m in model.masses.items():
        out["conm2"].append({"eid": eid, "node": m.nid, "cid": m.cid, "mass": m.mass, "x": [_f(v) for v in m.X],
                             "inertia": [[float(v) for v in row] for row in m.Inertia()]})
    for pid, p in model.properties.items():
        if p.type == "PSHELL":
            out["pshell"][pid] = {"mid1": p.mid1, "mid2": p.mid2, "mid3": p.mid3, "t": p.t,
                                  "twelveIt3": p.twelveIt3, "tst": p.tst, "nsm": p.nsm}
        elif p.type == "PBAR":
            out["pbar"][pid] = {"mid": p.mid, "A": p.A, "i1": p.i1, "i2": p.i2, "i12": p.i12, "j": p.j,
                                "nsm": p.nsm, "k1": _f(p.k1), "k2": _f(p.k2)}
        elif p.type == "PBUSH":
            out["pbush"][pid] = {"k": [_f(v) for v in p.Ki]}
    for mid, m in model.materials.items():
        if m.type == "MAT1":
            out["mat1"][mid] = {"E": m.e, "G": m.g, "nu": m.nu, "rho": m.rho}
        elif m.type == "MAT2":
            out["mat2"][mid] = {"G": [[m.G11, m.G12, m.G13], [m.G12, m.G22, m.G23], [m.G13, m.G23, m.G33]],
                                "rho": m.rho}
    for cid, c in model.coords.items():
        if cid:
            out["coords"][cid] = [[float(v) for v in row] for row in c.beta()]
    for spcs in model.spcs.values():
        for s in spcs:
            out["spc1"].append({"components": s.components, "nodes": s.node_ids})
    for mpcs in model.mpcs.values():
        for m in mpcs:
            out["mpc"].append({"nodes": m.node_ids, "components": m.components, "coefficients": m.coefficients})
    return out


if __name__ == "__main__":
    json.dump(dump(sys.argv[1]), sys.stdout)
