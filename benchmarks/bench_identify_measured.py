"""``identify`` on measured FRFs from outside the project (issue 38), beside sdypy-EMA run directly on the
same data.

Data: pyuff's measured accelerances (ladisk/pyuff, data/measurement.uff as of commit e2089be, MIT; in
../shared/realdata/pyuff, or $PCBDYN_REALDATA): a free beam struck at three points and read at one,
0-1000 Hz in 1 Hz lines, no geometry. No table of its identified modes is published; its bending modes
are the free-free Euler-Bernoulli beam's, whose frequency ratios are (beta_n L)^2 / (beta_1 L)^2 (Blevins,
Formulas for natural frequency and mode shape, table 8-1). The reference frequencies are sdypy-EMA's
(LSCF to the same order, poles chosen at the FRF peaks, its non-interactive path: the user names the
frequencies); pcbdyn's automatic choice is scored against them (found within 1 %, extra modes) on the
three FRFs together and on each alone (single reference and single response). Prints the table and the
counts; exits 1 when the folder is absent.

Run: python benchmarks/bench_identify_measured.py
"""

from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.signal import find_peaks  # noqa: E402

from pcbdyn.identification import identify  # noqa: E402
from pcbdyn.testdata import FRFs, Points, read_uff  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
REALDATA = Path(os.environ.get("PCBDYN_REALDATA", ROOT.parent / "shared" / "realdata"))
FILE = REALDATA / "pyuff" / "measurement_e2089be.uff"
BAND = (20.0, 1000.0)
POLES = 40
BETA_L = np.array([4.73004, 7.85320, 10.99561, 14.13717, 17.27876, 20.42035])


def sdypy_reference(frfs, band=BAND):
    """sdypy-EMA's LSCF on every FRF in ``band``, poles chosen nearest the peaks of the summed FRF magnitude
    (prominence of e, i.e. 8.7 dB); its frequencies [Hz], damping ratios and time."""
    from sdypy import EMA

    f = frfs.frequencies
    keep = (f >= band[0]) & (f <= band[1])
    rows = np.array([frfs.H[keep, 0, j] for j in range(frfs.H.shape[2])])
    mag = np.log(np.abs(rows).sum(axis=0))
    peaks, _ = find_peaks(mag, prominence=1.0)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = EMA.Model(frf=rows, freq=f[keep], lower=band[0], upper=band[1], pol_order_high=POLES,
                          frf_form=frfs.kind)
        model.get_poles("lscf", show_progress=False)
        model.select_closest_poles(f[keep][peaks])
    return np.asarray(model.nat_freq), np.asarray(model.nat_xi), time.perf_counter() - t0


def score(found, ref) -> tuple:
    """(reference modes found within 1 %, extra modes) of ``found`` against ``ref``."""
    d = np.abs(found[None, :] / ref[:, None] - 1) if found.size else np.ones((ref.size, 1))
    hit = d.min(axis=1) <= 0.01
    used = set(np.argmin(d, axis=1)[hit].tolist())
    return int(hit.sum()), int(found.size - len(used))


def main() -> int:
    if not FILE.is_file():
        print(f"{FILE}: not found (the third-party files are not beside this clone)", file=sys.stderr)
        return 1
    frfs = read_uff(FILE, points=Points([1, 2, 3], np.zeros((3, 3)))).frfs
    f_ref, z_ref, t_sd = sdypy_reference(frfs)
    runs = {"all three FRFs": frfs}
    for j in range(3):
        runs[f"FRF {j + 1} alone"] = FRFs(frfs.points, frfs.frequencies, frfs.H[:, :, j:j + 1], frfs.kind,
                                          frfs.response, frfs.reference.take([j]))
    found = {}
    for name, data in runs.items():
        t0 = time.perf_counter()
        found[name] = identify(data, BAND, POLES)
        found[name].seconds = time.perf_counter() - t0
    print(f"{FILE.name}: {frfs.H.shape[2]} accelerances, {BAND[0]:g}-{BAND[1]:g} Hz, LSCF to order {2 * POLES}")
    print(f"\n{'mode':>4} {'ratio (Blevins)':>15} {'sdypy-EMA f [Hz]':>17} {'ratio':>7}"
          + "".join(f" {name:>16}" for name in runs))
    for k, f in enumerate(f_ref):
        row = f"{k + 1:4d} {BETA_L[k] ** 2 / BETA_L[0] ** 2:15.4f} {f:17.2f} {f / f_ref[0]:7.4f}"
        for name in runs:
            fr = found[name].modes.frequencies
            near = fr[np.argmin(np.abs(fr - f))] if fr.size else np.nan
            row += f" {near:16.2f}"
        print(row)
    print(f"\nsdypy-EMA (poles named at the peaks): {f_ref.size} modes, damping {np.round(100 * z_ref, 3)} %, "
          f"{t_sd:.1f} s")
    for name in runs:
        fr = found[name].modes.frequencies
        hit, extra = score(fr, f_ref)
        print(f"pcbdyn automatic, {name}: {hit} of {f_ref.size} within 1 % ({100 * hit / f_ref.size:.0f} %), "
              f"{extra} extra ({', '.join(f'{x:.1f}' for x in fr if np.min(np.abs(f_ref / x - 1)) > 0.01) or '-'} Hz),"
              f" {found[name].seconds:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
