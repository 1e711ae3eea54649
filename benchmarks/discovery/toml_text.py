"""board.toml texts of a drawn case (:mod:`cases`): the one handed to ``pcbdyn diagnose`` (nominal
values, ``[[parameters]]`` for what is uncertain) and the true one (true values, the hidden effects
declared as board entries, meshed finer)."""

from __future__ import annotations

from cases import Case

#: how a parameter's SI value is written, by the unit its case keeps
SHOWN = {"Pa": (1e-9, "GPa"), "mm": (1e3, "mm"), "N/m": (1.0, "N/m"), "N*m/rad/m": (1.0, "N*m/rad/m")}


def quantity_text(value: float, unit: str) -> str:
    """``value`` [SI] as a quoted quantity in the unit a case file shows for ``unit``."""
    scale, shown = SHOWN.get(unit, (1.0, unit))
    return f'"{value * scale:.6g} {shown}"'


def _mm(v) -> str:
    return f'"{v:.6g} mm"'


def _pt(p) -> str:
    return f"[{_mm(p[0])}, {_mm(p[1])}]"


def declared_values(case: Case, truth: bool) -> dict:
    """{target: SI value} of the declared parameters (nominal or true)."""
    return {t: (p["true"] if truth else p["nominal"]) for p in case.parameters for t in p["targets"]}


def _part(p: dict, values: dict) -> str:
    out = (f'\n[[components]]\nref = "{p["ref"]}"\nat = {_pt(p["at"])}\nsize = [{_mm(p["size"][0])}, {_mm(p["size"][1])}]\n'
           f'mass = "{1e3 * p["mass"]:.6g} g"\nmodel = "{p["model"]}"\n')
    if "height_mm" in p:
        out += f'height = {_mm(p["height_mm"])}\n'
    if p["model"] == "equivalent_thickness":
        t = values.get(f"components.{p['ref']}.thickness", 1e-3 * p["thickness_mm"])
        out += f'thickness = {quantity_text(t, "mm")}\n'
    if p["model"] == "smeared_local":
        out += f'E = {quantity_text(p["E"], "Pa")}\n'
    return out


def _fixture(f: dict, values: dict) -> str:
    out = f'\n[[fixtures]]\nname = "{f["name"]}"\ntype = "{f["type"]}"\n'
    if "edge" in f:
        out += f'edge = "{f["edge"]}"\n'
    if f["type"] == "wedge_lock":
        k = values.get(f"fixtures.{f['name']}.k_rot", f["k_rot"])
        out += f'k_rot = {quantity_text(k, "N*m/rad/m")}\n'
    if f["type"] == "standoff":
        out += f'at = {_pt(f["at"])}\n'
        k = values.get(f"fixtures.{f['name']}.k", f["k"])
        out += 'k = "rigid"\n' if k is None else f'k = {quantity_text(k, "N/m")}\n'
    return out


def _effect(e: dict) -> str:
    """The hidden effect ``e`` as board entries of the true board."""
    n, k = e["name"], e["kind"]
    if k in ("point_mass", "bracket"):
        out = f'\n[[masses]]\nname = "{n}"\nat = {_pt(e["at"])}\nmass = "{1e3 * e["mass"]:.6g} g"\n'
        if k == "bracket":
            out += (f'\n[[fixtures]]\nname = "{n}_spring"\ntype = "point_spring"\nat = {_pt(e["at"])}\n'
                    f'k = {quantity_text(e["k"], "N/m")}\n')
        return out
    if k == "ground_spring":
        return f'\n[[fixtures]]\nname = "{n}"\ntype = "point_spring"\nat = {_pt(e["at"])}\nk = {quantity_text(e["k"], "N/m")}\n'
    if k == "standoff":
        return f'\n[[fixtures]]\nname = "{n}"\ntype = "standoff"\nat = {_pt(e["at"])}\n'
    if k == "stiffener":
        section = (f'{{ E = {quantity_text(e["E"], "Pa")}, nu = 0.3, rho = "{e["rho"]:.6g} kg/m^3", '
                   f'height = {_mm(e["height_mm"])} }}')
        return (f'\n[[stiffeners]]\nname = "{n}"\npath = [{_pt(e["path"][0])}, {_pt(e["path"][1])}]\n'
                f'EI = "{e["EI"]:.6g} N*m^2"\nsection = {section}\n')
    if k == "heat_sink":
        return (f'\n[[components]]\nref = "{n}"\nat = {_pt(e["at"])}\nsize = [{_mm(e["size"][0])}, {_mm(e["size"][1])}]\n'
                f'mass = "{1e3 * e["mass"]:.6g} g"\nmodel = "smeared_local"\nE = {quantity_text(e["E"], "Pa")}\n')
    if k == "line_mass":
        a, b = e["segment"]
        return f'\n[[line_masses]]\nname = "{n}"\nfrom = {_pt(a)}\nto = {_pt(b)}\nmass = "{1e3 * e["mass"]:.6g} g"\n'
    if k == "edge_stiffness":
        a, b = e["segment"]
        return (f'\n[[fixtures]]\nname = "{n}"\ntype = "edge_spring"\nfrom = {_pt(a)}\nto = {_pt(b)}\n'
                f'k_rot = {quantity_text(e["k_rot"], "N*m/rad/m")}\n')
    if k == "region":
        x0, y0, x1, y1 = e["rect"]
        return f'\n[[regions]]\nname = "{n}"\nrect = [{_mm(x0)}, {_mm(y0)}, {_mm(x1)}, {_mm(y1)}]\nstiffness_factor = {e["factor"]:.6g}\n'
    raise ValueError(k)


def parameters_text(parameters) -> str:
    """``[[parameters]]`` entries of a case's declared parameters, within their bounds."""
    out = ""
    for p in parameters:
        lo, hi = p["bounds"]
        targets = ", ".join(f'"{t}"' for t in p["targets"])
        out += (f'\n[[parameters]]\nname = "{p["name"]}"\ntarget = [{targets}]\n'
                f'bounds = [{quantity_text(lo, p["unit"])}, {quantity_text(hi, p["unit"])}]\n')
    return out


def board_text(case: Case, truth: bool = False, mesh_mm: float | None = None) -> str:
    """The handed board.toml (``truth`` False) or the true one (true values, hidden effects declared)."""
    values = declared_values(case, truth)
    E = values.get("board.E", case.E)
    out = (f'# discovery case {case.name} ({"truth" if truth else "handed to diagnose"}), drawn by '
           f'benchmarks/discovery/cases.py\n[board]\nname = "{case.name}"\n'
           f'outline = {{ polygon = [{", ".join(_pt(p) for p in case.outline)}] }}\n'
           f'thickness = {_mm(case.thickness_mm)}\n'
           f'material = {{ E = {quantity_text(E, "Pa")}, nu = {case.nu:g}, rho = "{case.rho:g} kg/m^3" }}\n'
           f'mesh_size = {_mm(mesh_mm or case.mesh_mm)}\n')
    out += "".join(_part(p, values) for p in case.parts)
    out += "".join(_fixture(f, values) for f in case.fixtures)
    if truth:
        out += "".join(_effect(e) for e in case.effects)
    else:
        out += parameters_text(case.parameters)
    out += f"\n[analysis]\nmodes = {case.test_modes + 4}\n"
    return out
