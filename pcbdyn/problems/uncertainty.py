"""What a board's predicted frequencies inherit from its component library: the standard deviations of
the calibrated family values (``equivalent_thickness_std``, written by ``pcbdyn calibrate``)
propagated to each frequency to first order through the sensitivities (thesis eq. 3.6),
sd_f_i^2 = sum_j (df_i/dp_j)^2 sd_j^2, the families taken as independent."""

from __future__ import annotations

import numpy as np

from ..components.library import locate, read_package
from ..updating.sensitivity import frequency_derivatives
from .calibration import families_on, family_structure
from .models import parameter_derivatives


def library_uncertainty(structure) -> tuple:
    """(the structure with one parameter per family that carries a standard deviation in the library,
    and no other parameters; {family: (value [m], std [m], [refs])}). Only parts that take the
    library's value (equivalent thickness model, no thickness of their own in the file) inherit its
    uncertainty."""
    start, parts, out = {}, {}, {}
    for fam, cs in families_on(structure).items():
        path = locate(fam, structure.path.parent)
        pkg = read_package(path) if path is not None else None
        if pkg is None or not pkg.equivalent_thickness_std:
            continue
        own = [c for c in cs if c.model == "equivalent_thickness" and c.thickness == pkg.equivalent_thickness]
        if own:
            start[fam], parts[fam] = (pkg.equivalent_thickness, path), own
            out[fam] = (pkg.equivalent_thickness, pkg.equivalent_thickness_std, [c.ref for c in own])
    return family_structure(structure, start, (), parts), out


def frequency_std(pm, modes, stds: dict) -> np.ndarray:
    """Standard deviation [Hz] of each elastic mode of ``modes`` (:class:`pcbdyn.fe.modal.Modes`, of the
    built model ``pm``) from the families' {name: (value, std, refs)} of :func:`library_uncertainty`."""
    names = list(stds)
    if not names or modes.frequencies.size == 0:
        return np.zeros(modes.frequencies.size)
    pairs = parameter_derivatives(pm, names)
    df = frequency_derivatives(modes.omega2, modes.shapes, [dK for dK, _ in pairs], [dM for _, dM in pairs])
    sd = np.array([stds[n][1] for n in names])
    return np.sqrt((df**2) @ sd**2)
