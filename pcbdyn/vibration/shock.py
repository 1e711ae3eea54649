"""A board's verdict under shock: a pulse or an acceleration record through the fixtures by modal
transient response, or a shock response spectrum by combined peak modal responses; the peak
relative displacement, absolute acceleration and curvature at every part, Steinberg's shock
allowable per part, and the SRS of the input. This is what ``pcbdyn shock`` reports.

Transient: with the base acceleration a(t) along ``axis``, each mode obeys
q_r'' + 2 zeta_r w_r q_r' + w_r^2 q_r = -Gamma_r a(t) (thesis eq. 3.27 with the inertial load of
:mod:`.base_excitation`, in modal coordinates), integrated exactly for the piecewise-linear a(t)
(:mod:`.transient`); the modes left out respond statically, u = sum phi_r q_r - R a(t) (R the static
residual of :mod:`.base_excitation`). The absolute acceleration is r a + sum phi_r q_r'' (the modes
left out move with the base: their own acceleration -R a'' is left out, a train of impulses for a
piecewise-linear input). The response is followed ``WINDOW_CYCLES`` periods of the fundamental past
the end of the input; peaks are sampled ``POINTS_PER_CYCLE`` times per period of the highest mode.

SRS input: the peak of mode r is |Gamma_r| S(f_r) / w_r^2 (S read at the mode's frequency, held at
its end values outside its band); the modes left out add R times the spectrum's last value (the
zero-period acceleration: the missing mass) as one more term; the terms at each output are combined
by SRSS, absolute sum or NRL (:func:`.srs.combine`). No times then.

Steinberg's criterion for shock: the peak relative displacement z at a part against six times his
vibration allowable (:func:`.steinberg.shock_allowable_displacement`, judged as ``vibe`` judges, on
the part's own displacement with the allowable Z(1)); ratio = z / z_allow.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fe.effective_mass import EffectiveMass
from . import steinberg
from .assess import board_excitation
from .base_excitation import BaseExcitation
from .damping import Damping
from .parts import PartVerdict, judged_parts, part_readers, shell_nodes
from .pulses import SrsSpec, Transient
from .spectra import G
from .srs import octave_points, pseudo_velocity, srs
from .srs import combine as combine_peaks
from .transient import Oscillators, Peaks, refine, states

#: samples per period of the highest mode kept (at the parts; the board map every ``MAP_STRIDE``-th)
POINTS_PER_CYCLE = 40
MAP_STRIDE = 4
#: periods of the fundamental the response is followed past the end of the input
WINDOW_CYCLES = 2.0
#: a pulse's modes are computed up to this many over its duration (an oscillator above responds to
#: it nearly statically: a half-sine's SRS at Q = 10 is within 1.1 % of its peak from 10 / T up)
PULSE_BAND = 10.0


def analysis_band(inp) -> float:
    """The frequency [Hz] up to which modes are computed (the static residual takes the rest): ten
    over a pulse's duration, a record's Nyquist frequency, the top of an SRS."""
    if isinstance(inp, SrsSpec):
        return float(inp.f[-1])
    if inp.kind == "history":
        return 0.5 / float(np.diff(inp.t).min())
    return PULSE_BAND / inp.duration


@dataclass
class ShockPart(PartVerdict):
    """Steinberg's shock check of one part (SI; times None for an SRS input); its margin
    z_allow / z - 1 is negative when it fails Steinberg's shock criterion."""

    z_peak_m: float
    t_peak_s: float | None
    z_allow_m: float
    z_allow_board_m: float | None
    ratio: float
    accel_peak_g: float
    t_accel_s: float | None
    curvature_peak_1pm: float
    t_curvature_s: float | None

    @property
    def ok(self) -> bool:
        return self.ratio <= 1.0


@dataclass
class ShockAssessment:
    """Everything ``pcbdyn shock`` reports, SI inside (see :meth:`to_dict` for the JSON)."""

    input: Transient | SrsSpec
    damping: Damping
    axis: str
    excitation: BaseExcitation
    damping_source: list
    parts: list
    node_z_peak: np.ndarray  # (n_nodes,) peak relative displacement normal to the board [m], NaN off the shells
    srs_f: np.ndarray
    srs_value: np.ndarray  # [m/s^2]
    srs_q: float
    combination: str | None  # SRS input only
    followed_s: float | None  # transient: the end of the time followed [s]
    effective_mass: EffectiveMass | None = None
    notes: list = field(default_factory=list)

    @property
    def z_peak_m(self) -> float:
        return float(np.nanmax(self.node_z_peak))

    def to_dict(self) -> dict:
        """The JSON contract: input (kind, peak, duration), modes[] (frequency_hz, damping_ratio,
        participation), parts[] (ref, z_peak_m, curvature_peak_1pm, z_allow_m, ratio, t_peak_s, ...)
        worst margin first, srs (frequency, value), and the rest."""
        be, inp = self.excitation, self.input
        return {
            "input": {"kind": inp.kind, "name": inp.name, "source": inp.source, "peak": inp.peak / G, "peak_unit": "g",
                      "duration": inp.duration, "duration_unit": "s",
                      "combination": self.combination},
            "axis": self.axis,
            "damping": self.damping.describe(),
            "modes": [{"n": i + 1, "frequency_hz": float(f), "damping_ratio": float(z), "participation": float(g),
                       "effective_mass": m, "damping_source": s}
                      for i, (f, z, g, m, s) in enumerate(zip(be.frequencies, be.zeta, be.gamma,
                                                              self.effective_mass.as_dicts(), self.damping_source))],
            "participation_unit": "kg^0.5",
            "effective_mass_fraction": self.effective_mass.share(self.axis),
            "z_peak_m": self.z_peak_m,
            "followed_s": self.followed_s,
            "parts": [p.to_dict() for p in self.parts],
            "srs": {"frequency": self.srs_f.tolist(), "value": (self.srs_value / G).tolist(),
                    "pseudo_velocity": pseudo_velocity(self.srs_f, self.srs_value).tolist(),
                    "unit": {"frequency": "Hz", "value": "g", "pseudo_velocity": "m/s"}, "q": self.srs_q,
                    "kind": "maximax absolute acceleration" if inp.kind != "srs" else "the specification"},
            "ok": all(p.ok for p in self.parts),
            "notes": self.notes,
        }


def transient_peaks(be: BaseExcitation, t, a, displacement: dict, acceleration: dict, until: float,
                    sparse: tuple = ()) -> dict:
    """{name: :class:`.transient.Peaks`} of the outputs read by each matrix of ``displacement``
    (rows on the columns [modes, R]) and of ``acceleration`` (rows on [r, modes, R]) under the base
    acceleration (``t``, ``a``) (zero after it) from t[0] to ``until`` [s]; the outputs named in
    ``sparse`` (a whole board's nodes) are read at every ``MAP_STRIDE``-th point only."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    if a[-1] != 0.0:  # zero after the record: a jump
        t, a = np.append(t, t[-1]), np.append(a, 0.0)
    if until > t[-1]:
        t, a = np.append(t, until), np.append(a, 0.0)
    osc = Oscillators(be.frequencies, be.zeta)
    tt, aa, h = refine(t, a, 1.0 / (POINTS_PER_CYCLE * be.frequencies[-1]))
    w2, zw, gamma = osc.w**2, osc.zeta * osc.w, be.gamma
    peaks = {k: Peaks(B.shape[0]) for k, B in (*displacement.items(), *acceleration.items())}
    for k0, y in states(osc, aa, h):
        tb, ab = tt[k0:k0 + y.shape[0]], aa[k0:k0 + y.shape[0]]
        z, zd = osc.displacement(y)
        q = np.column_stack([-gamma * z, -ab])
        for k, B in displacement.items():
            every = MAP_STRIDE if k in sparse else 1
            peaks[k].update(tb[::every], q[::every] @ B.T)
        if acceleration:
            qdd = -gamma * (ab[:, None] - 2.0 * zw * zd - w2 * z)
            qa = np.column_stack([ab, qdd, np.zeros_like(ab)])
            for k, B in acceleration.items():
                peaks[k].update(tb, qa @ B.T)
    return peaks


def spectrum_peaks(be: BaseExcitation, spec: SrsSpec, displacement: dict, acceleration: dict, rule: str) -> dict:
    """{name: combined peak of each output row} under the shock response spectrum ``spec`` (see the
    module), rows as in :func:`transient_peaks`."""
    n, w2 = be.frequencies.size, (2.0 * np.pi * be.frequencies) ** 2
    s, zpa = spec.at(be.frequencies), float(spec.value[-1])
    out = {}
    for k, B in displacement.items():
        terms = np.column_stack([B[:, :n] * (be.gamma * s / w2), B[:, n] * zpa])
        out[k] = combine_peaks(terms, rule)
    for k, B in acceleration.items():
        modal = B[:, 1:n + 1] * be.gamma
        out[k] = combine_peaks(np.column_stack([modal * s, (B[:, 0] - modal.sum(axis=1)) * zpa]), rule)
    return out


def _part_results(board, parts, peaks: dict, z_board: float, timed: bool) -> list:
    h = board.thickness
    out = []
    for j, p in enumerate(parts):
        def get(k):
            v = peaks[k]
            return (float(v.magnitude[j]), float(v.time[j]) if timed else None) if isinstance(v, Peaks) \
                else (float(v[j]), None)

        (z, tz), (acc, ta) = get("z"), get("acceleration")
        (k1, t1), (k2, t2) = get("curvature_along"), get("curvature_across")
        kappa, tk = (k1, t1) if k1 >= k2 else (k2, t2)
        z_allow = steinberg.shock_allowable_displacement(p.span, p.length, h, p.c)
        r = z / z_board if z_board > 0 else 0.0
        out.append(ShockPart(p.ref, p.package, p.c, p.span, p.length, r, z, tz, z_allow,
                             steinberg.shock_allowable_displacement(p.span, p.length, h, p.c, r) if r > 0 else None,
                             z / z_allow, acc / G, ta, kappa, tk))
    return sorted(out, key=lambda x: x.margin)


def assess_shock(board, bm, modes, K, M, inp: Transient | SrsSpec, damping: Damping, *, axis: str = "z",
                 parts=None, combination: str = "srss", srs_band=(10.0, 10000.0), srs_q: float = 10.0,
                 probe_tol: float | None = None) -> ShockAssessment:
    """Judge the solved board model ``bm`` (``modes``, assembled ``K``, ``M``) under the shock ``inp``
    along ``axis``: the peaks at every part (worst margin first) and over the board, and the SRS of
    the input over ``srs_band`` [Hz] at quality factor ``srs_q`` (an SRS input is its own);
    ``combination`` (srss, abs, nrl) combines modal peaks under an SRS input; ``parts`` and
    ``probe_tol`` as in :func:`.assess.assess`."""
    parts = judged_parts(board) if parts is None else parts
    model = bm.model
    be, source, em, notes = board_excitation(board, bm, modes, K, M, damping, axis, probe_tol)
    nodes = shell_nodes(model)
    disp = {"nodes": be.basis[6 * nodes + 2]}
    acc = {}
    if parts:
        read = part_readers(model, parts, axis)
        disp.update({k: be.columns(read[k]) for k in ("z", "curvature_along", "curvature_across")})
        acc = {"acceleration": be.columns(read["acceleration"], "acceleration")}
    timed = isinstance(inp, Transient)
    if timed:
        until = float(inp.t[-1]) + WINDOW_CYCLES / float(be.frequencies[0])
        peaks = transient_peaks(be, inp.t, inp.a, disp, acc, until, sparse=("nodes",))
        node_peak = peaks["nodes"].magnitude
        f_srs = octave_points(*srs_band)
        s_srs, q_srs, rule = srs(inp.t, inp.a, f_srs, srs_q), srs_q, None
        notes.append(f"response followed to {until * 1e3:.4g} ms ({WINDOW_CYCLES:g} periods of the fundamental past "
                     "the input's end)")
    else:
        until, rule = None, combination
        peaks = spectrum_peaks(be, inp, disp, acc, combination)
        node_peak = peaks["nodes"]
        f_srs = octave_points(inp.f[0], inp.f[-1])
        s_srs, q_srs = inp.at(f_srs), inp.q
        if be.frequencies[0] < inp.f[0]:
            notes.append(f"the fundamental ({be.frequencies[0]:.0f} Hz) lies below the spectrum's band "
                         f"({inp.f[0]:g} Hz): its value there is held at the band's first value")
    node_z = np.full(model.nodes.shape[0], np.nan)
    node_z[nodes] = node_peak
    results = _part_results(board, parts, peaks, float(np.nanmax(node_z)), timed) if parts else []
    return ShockAssessment(inp, damping, axis, be, source, results, node_z, f_srs, s_srs, q_srs, rule, until, em,
                           notes)
