"""FRF tests of a structure's configurations (UFF dataset 58 files) as driver configurations of the FRF
methods, with the frequency configurations the before/after tables are made of."""

from __future__ import annotations

from ..testdata import MeasuredModes, TestDataError, excitations, read_uff
from ..updating.frf_lines import resonance_lines


def frf_configurations(problem, files, method: str, freqs=None, damping: str = "undamped", structure: int = 0):
    """(check, cfgs, notes) for ``files`` [(configuration or None, UFF path)]: ``cfgs`` the FRF
    configurations of every excitation of every file (:meth:`.problem.UpdateProblem.frf_configurations`),
    ``check`` one frequency configuration per file for the before/after tables (the file's modes,
    dataset 55, paired by MAC; without modes its FRF peaks paired by order) and ``notes`` for the user."""
    check, cfgs, notes = [], [], []
    for name, path in files:
        td = read_uff(path)
        if td.frfs is None:
            raise TestDataError(f"{path}: no FRFs (UFF dataset 58) in the file; --method {method} needs measured FRFs "
                                "(write them with 'pcbdyn simulate-test' or export them from the test)")
        meas = excitations(td.frfs)
        got, more = problem.frf_configurations(name, meas, method, freqs=freqs, damping=damping, structure=structure)
        notes += [f"{path.name}: {n}" for n in more]
        notes.append(f"{path.name}: updating frequencies " + ", ".join(f"{f:.1f}" for f in got[0].frf_hz) + " Hz")
        cfgs += got
        if td.modes is not None and td.modes.n_modes:
            check.append(problem.configuration(name, td.modes, "freq", structure=structure))
        else:
            notes.append(f"{path.name}: no modes in the file; the before/after tables use its FRF peaks paired by order")
            check.append(problem.configuration(name, MeasuredModes.frequencies_only(resonance_lines(meas[0].frequencies, meas[0].H)),
                                               "freq", structure=structure))
    return check, cfgs, notes
