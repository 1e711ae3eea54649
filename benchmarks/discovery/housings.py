"""Ribbed housings drawn from a seed: the box side of the discovery benchmark (issue 37: "ribbed boxes,
3-5 plates, 0-6 ribs, held on one face"), beside the boards of :mod:`cases`.

A housing is 3-5 aluminium plates of one thickness (1.5-3 mm): two side walls and a back wall or an
upper plate, then the other, then a front wall, the walls clamped along the base they stand on. 0-6
ribs run edge to edge on the plates' inner faces, one height per plate. Declared values a few % to
40 % off (:func:`cases._parameter`): one plate's E and rho and the rib height of up to two plates. 0-2
hidden effects: a point mass on a plate (a relay, a transformer) or a rib the description lacks (a bar
of aluminium or steel that may stop short of the edges, in any direction, with its mass). 20-120
points on the plates, each measured in x, y and z. The truth is solved in OpenSees (ASDShellQ4, the
ribs as offset beams) on a mesh half the model's; the test has pcbdyn's noise model.

Housing seeds use the boards' split ranges (dev 0-199, report 1000-1199) and are kept in the cache as
``h0000``...; ``make.py`` and ``run.py`` take them as ``h0-9`` (``run.py`` also ``dev-housings``,
``report-housings``).

    python benchmarks/discovery/make.py h0-3 [--cache DIR]
"""

from __future__ import annotations

import hashlib
import json
import sys
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import shapely

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from cases import _loguniform, _parameter, _segment_in  # noqa: E402
from make import ZETA, cache_dir, cached  # noqa: E402
from seen import EXTRA_MODES  # noqa: E402
from toml_text import declared_values, parameters_text, quantity_text  # noqa: E402

E_AL, NU_AL, RHO_AL = 70e9, 0.33, 2700.0
#: hidden effect kinds on housings and their weights
HOUSING_EFFECTS = {"point_mass": 0.6, "stiffener": 0.4}
NOISE = (0.2, 2.0)
TEST_MODES = 10
SHELL = "ASDShellQ4"
TRUTH_REFINEMENT = 2.0
#: walls stand on the base along their edge v = 0 (the box frame: x across, y front to back, z up)
WALLS = ("left", "right", "back", "front")


@dataclass
class Housing:
    """A drawn housing; lengths in mm, other quantities SI."""

    seed: int
    size_mm: list  # [x, y, z]
    plates: list  # [{name, origin, u, v, inner}] mm; inner: the rib side "+n" or "-n"
    thickness_mm: float
    mesh_mm: float
    ribs: list = field(default_factory=list)  # [{name, plate, from, to, height_mm, width_mm}] plate coordinates
    parameters: list = field(default_factory=list)  # {name, targets, unit, nominal, true, bounds}
    effects: list = field(default_factory=list)
    points: list = field(default_factory=list)  # [[x, y, z], ...] mm, box frame
    noise: tuple = NOISE
    test_modes: int = TEST_MODES
    shell: str = SHELL
    hold: str = "housing"

    @property
    def name(self) -> str:
        return f"h{self.seed:04d}"

    def to_json(self) -> dict:
        return asdict(self)


def _plates(rng, a, b, c) -> list:
    every = {"left": ([0, 0, 0], [0, b, 0], [0, 0, c], "+n"), "right": ([a, 0, 0], [0, b, 0], [0, 0, c], "-n"),
             "back": ([0, b, 0], [a, 0, 0], [0, 0, c], "+n"), "front": ([0, 0, 0], [a, 0, 0], [0, 0, c], "-n"),
             "upper": ([0, 0, c], [a, 0, 0], [0, b, 0], "-n")}
    n = int(rng.integers(3, 6))
    names = {3: ["left", "right", "back" if rng.random() < 0.5 else "upper"], 4: ["left", "right", "back", "upper"],
             5: list(every)}[n]
    return [{"name": k, "origin": every[k][0], "u": every[k][1], "v": every[k][2], "inner": every[k][3]}
            for k in names]


def _sides(p) -> tuple:
    return float(np.linalg.norm(p["u"])), float(np.linalg.norm(p["v"]))


def xyz(p, st) -> list:
    """Box-frame point [mm] of plate coordinates ``st`` [mm] on plate ``p``."""
    lu, lv = _sides(p)
    q = np.asarray(p["origin"], float) + st[0] / lu * np.asarray(p["u"], float) + st[1] / lv * np.asarray(p["v"], float)
    return [round(float(v), 3) for v in q]


def _by_area(rng, plates):
    areas = np.array([np.prod(_sides(p)) for p in plates])
    return plates[int(rng.choice(len(plates), p=areas / areas.sum()))]


def _ribs(rng, h: Housing) -> None:
    heights = {}
    for i in range(int(rng.integers(0, 7))):
        p = _by_area(rng, h.plates)
        lu, lv = _sides(p)
        along_u = rng.random() < 0.5
        span, across = (lu, lv) if along_u else (lv, lu)
        at = round(float(rng.uniform(0.15, 0.85) * across), 2)
        same = [r for r in h.ribs if r["plate"] == p["name"] and (r["from"][1] == r["to"][1]) == along_u]
        if any(abs((r["from"][1] if along_u else r["from"][0]) - at) < 15.0 for r in same):
            continue
        ends = ([0.0, at], [span, at]) if along_u else ([at, 0.0], [at, span])
        height = heights.setdefault(p["name"], round(float(rng.uniform(5.0, 15.0)), 2))
        h.ribs.append({"name": f"{p['name']}_r{i + 1}", "plate": p["name"], "from": ends[0], "to": ends[1],
                       "height_mm": height, "width_mm": round(float(rng.uniform(2.0, 4.0)), 2)})


def _effect(rng, h: Housing, kind: str):
    p = _by_area(rng, h.plates)
    lu, lv = _sides(p)
    if kind == "point_mass":
        st = [round(float(rng.uniform(5.0, lu - 5.0)), 2), round(float(rng.uniform(5.0, lv - 5.0)), 2)]
        return {"kind": kind, "plate": p["name"], "st": st, "at": xyz(p, st), "mass": _loguniform(rng, 0.5e-3, 150e-3)}
    seg = _segment_in(rng, shapely.box(3.0, 3.0, lu - 3.0, lv - 3.0), (0.3 * max(lu, lv), max(lu, lv)))
    if seg is None:
        return None
    steel = rng.random() < 0.5
    E, rho = (200e9, 7850.0) if steel else (E_AL, RHO_AL)
    w, t = _loguniform(rng, 1.5, 8.0), _loguniform(rng, 1.0, 12.0)
    return {"kind": kind, "plate": p["name"], "st": seg, "path": [xyz(p, s) for s in seg], "E": E, "rho": rho,
            "width_mm": round(w, 3), "height_mm": round(t, 3), "EI": E * (w * 1e-3) * (t * 1e-3) ** 3 / 12.0}


def _points(rng, h: Housing, n_target: int) -> list:
    """About ``n_target`` points, shared by the plates' areas: a jittered grid 3 mm in from the edges."""
    areas = np.array([np.prod(_sides(p)) for p in h.plates])
    out = []
    for p, share in zip(h.plates, areas / areas.sum()):
        lu, lv = _sides(p)
        n = max(4, int(round(n_target * share)))
        nu = max(2, int(round(np.sqrt(n * lu / lv))))
        nv = max(2, int(round(n / nu)))
        for i in range(nu):
            for j in range(nv):
                st = (3.0 + (i + 0.5 + rng.uniform(-0.3, 0.3)) * (lu - 6.0) / nu,
                      3.0 + (j + 0.5 + rng.uniform(-0.3, 0.3)) * (lv - 6.0) / nv)
                out.append(xyz(p, st))
    return out


def draw(seed: int) -> Housing:
    """The housing of ``seed``."""
    rng = np.random.default_rng([seed, 37])  # not the board of the same seed's stream
    a, b, c = (round(float(rng.uniform(*r)), 1) for r in ((120, 300), (100, 250), (60, 160)))
    h = Housing(seed, [a, b, c], _plates(rng, a, b, c), round(float(rng.uniform(1.5, 3.0)), 2),
                float(np.clip(round(max(a, b, c) / 20.0), 8.0, 14.0)))
    _ribs(rng, h)
    p = h.plates[int(rng.integers(len(h.plates)))]["name"]
    _parameter(rng, h, f"E_{p}", [f"plates.{p}.E"], "Pa", E_AL)
    _parameter(rng, h, f"rho_{p}", [f"plates.{p}.rho"], "kg/m^3", RHO_AL)
    ribbed = list(dict.fromkeys(r["plate"] for r in h.ribs))
    for q in rng.permutation(ribbed)[:2] if ribbed else []:
        mine = [r for r in h.ribs if r["plate"] == q]
        _parameter(rng, h, f"h_{q}", [f"ribs.{r['name']}.height" for r in mine], "mm", 1e-3 * mine[0]["height_mm"])
    n_eff = int(rng.choice([0, 1, 2], p=[0.25, 0.45, 0.30]))
    while len(h.effects) < n_eff:
        e = _effect(rng, h, str(rng.choice(list(HOUSING_EFFECTS), p=list(HOUSING_EFFECTS.values()))))
        if e is not None:
            e["name"] = f"hidden{len(h.effects) + 1}"
            h.effects.append(e)
    h.points = _points(rng, h, int(rng.integers(20, 121)))
    return h


# ------------------------------------------------------------------------------------------ box.toml
def _mm3(v) -> str:
    return "[" + ", ".join(f'"{x:.6g} mm"' for x in v) + "]"


def box_text(h: Housing, truth: bool = False, mesh_mm: float | None = None, effects=None) -> str:
    """The box.toml handed to diagnose (nominal values, ``[[parameters]]``) or the true one (true values,
    the hidden effects declared: ``effects``, default all of them)."""
    values = declared_values(h, truth)
    out = [f'[box]\nname = "{h.name}"\nmesh_size = "{mesh_mm or h.mesh_mm:g} mm"\n',
           f'[materials.al]\nE = "{E_AL / 1e9:g} GPa"\nnu = {NU_AL}\nrho = "{RHO_AL:g} kg/m^3"\n']
    for p in h.plates:
        s = (f'[[plates]]\nname = "{p["name"]}"\norigin = {_mm3(p["origin"])}\nu = {_mm3(p["u"])}\nv = {_mm3(p["v"])}\n'
             f'thickness = "{h.thickness_mm:g} mm"\nmaterial = "al"\n')
        E, rho = values.get(f"plates.{p['name']}.E"), values.get(f"plates.{p['name']}.rho")
        if E is not None:
            s += f'E = {quantity_text(E, "Pa")}\nrho = {quantity_text(rho, "kg/m^3")}\n'
        out.append(s)
    inner = {p["name"]: p["inner"] for p in h.plates}
    for r in h.ribs:
        height = 1e3 * values.get(f"ribs.{r['name']}.height", 1e-3 * r["height_mm"])
        out.append(f'[[ribs]]\nname = "{r["name"]}"\nplate = "{r["plate"]}"\nfrom = {_mm3(r["from"])}\nto = {_mm3(r["to"])}\n'
                   f'height = "{height:.6g} mm"\nwidth = "{r["width_mm"]:g} mm"\nside = "{inner[r["plate"]]}"\n')
    for w in (p["name"] for p in h.plates if p["name"] in WALLS):
        out.append(f'[[supports]]\nplate = "{w}"\nedge = "v0"\ntype = "clamped"\n')
    for e in (h.effects if effects is None else effects) if truth else []:
        if e["kind"] == "point_mass":
            out.append(f'[[masses]]\nname = "{e["name"]}"\nplate = "{e["plate"]}"\nat = {_mm3(e["st"])}\n'
                       f'mass = "{1e3 * e["mass"]:.6g} g"\n')
        else:
            out.append(f'[[ribs]]\nname = "{e["name"]}"\nplate = "{e["plate"]}"\nfrom = {_mm3(e["st"][0])}\n'
                       f'to = {_mm3(e["st"][1])}\nheight = "{e["height_mm"]:g} mm"\nwidth = "{e["width_mm"]:g} mm"\n'
                       f'side = "{inner[e["plate"]]}"\nmaterial = {{ E = "{e["E"] / 1e9:g} GPa", nu = 0.3, '
                       f'rho = "{e["rho"]:g} kg/m^3" }}\n')
    out.append(parameters_text(h.parameters))
    return "\n".join(out)


# -------------------------------------------------------------------------------------------- making
def measurement_points(h: Housing) -> tuple:
    """(Points, Dofs): each point measured in x, y and z."""
    from pcbdyn.testdata.data import Dofs, Points

    ids = np.arange(1, len(h.points) + 1)
    return (Points(ids, 1e-3 * np.asarray(h.points, float)),
            Dofs(np.repeat(ids, 3), np.tile(np.eye(3), (len(ids), 1))))


def _model(h: Housing, truth: bool, mesh_mm: float, effects=None):
    from pcbdyn.box import load_box

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "box.toml"
        path.write_text(box_text(h, truth, mesh_mm, effects))
        return load_box(path).build().model


def _read(model, h: Housing):
    from pcbdyn.fe.probe import model_probe

    points, dofs = measurement_points(h)
    return model_probe(model, points.xyz[points.index(dofs.point_ids)], dofs.directions, tol=0.02).P


def _state(h: Housing):
    """(frequencies, unit shapes at the measured DOFs) of ``h``'s truth on the model mesh (detectability)."""
    from pcbdyn.fe.modal import solve_modes

    model = _model(h, True, h.mesh_mm)
    modes = solve_modes(model, n_modes=h.test_modes + EXTRA_MODES)
    u = np.asarray(_read(model, h) @ modes.shapes)
    return modes.frequencies, u / np.linalg.norm(u, axis=0)


def code_key() -> str:
    """A digest of the code that makes a housing: a cached one made by other code is made again."""
    digest = hashlib.sha1()
    for name in ("housings.py", "cases.py", "toml_text.py", "opensees_truth.py", "detectability.py", "seen.py"):
        digest.update((HERE / name).read_bytes())
    return digest.hexdigest()[:12]


def make(seed: int, cache: Path | None = None) -> Path:
    """The folder of housing ``seed`` (made if missing): box.toml, points.csv, test.uff, truth.json."""
    from detectability import effect_chi2

    folder, key = (cache or cache_dir()) / f"h{seed:04d}", code_key()
    if not cached(folder, key):
        folder.mkdir(parents=True, exist_ok=True)
        h = draw(seed)
        f = _solve_and_write(h, folder)
        (folder / "truth.json").write_text(json.dumps({"key": key, "case": h.to_json(), "frequencies_hz": f.tolist(),
                                                       "signal_chi2": effect_chi2(h, _state)}, indent=1))
    return folder


def _solve_and_write(h: Housing, folder: Path) -> np.ndarray:
    """The housing's box.toml texts, its truth solved in OpenSees and its test written; the truth's
    frequencies [Hz]."""
    from opensees_truth import solve_opensees

    from pcbdyn.fe.modal import Modes as ModelModes
    from pcbdyn.testdata.csvio import write_points_csv
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_test
    from pcbdyn.testdata.uff import write_uff

    (folder / "box.toml").write_text(box_text(h))
    (folder / "truth.toml").write_text(box_text(h, truth=True, mesh_mm=h.mesh_mm / TRUTH_REFINEMENT))
    model = _model(h, True, h.mesh_mm / TRUTH_REFINEMENT)
    f, shapes = solve_opensees(model, h.test_modes, shell=h.shell)  # a test in x, y and z sees every mode
    u = np.asarray(_read(model, h) @ shapes.reshape(-1, shapes.shape[-1]))
    points, dofs = measurement_points(h)
    write_points_csv(folder / "points.csv", points, dofs)
    write_uff(folder / "test.uff", simulate_test(ModelModes(f, u, np.zeros((u.shape[0], 0)), None), points, dofs,
                                                 np.eye(u.shape[0]), zeta=ZETA,
                                                 noise=Noise(frequency_pct=h.noise[0], shape_pct=h.noise[1]),
                                                 seed=h.seed))
    return f
