"""A board's design verdict under a vibration specification: the random response at every part
and over the board, Steinberg's check and fatigue life per part, a sine sweep's damage, and the
octave rule. This is what ``pcbdyn vibe`` reports; it works on an already solved model.

Steinberg's criterion compares the 3-sigma displacement at the board's centre, Z_c, with his
allowable Z(r) for a part at relative position r (see :mod:`.steinberg`). His r is the ratio of the
board's displacement at the part to that at the centre, so Z_c <= Z(r) is the same as
z_part <= r Z(r) = Z(1): with the displacement at the part known from the model, the part is
judged on its own RMS relative displacement z against ``z_allow`` = Z(1), ratio = 3 z / z_allow.
The position factor is still reported, read from the model as r = z / z_peak (z_peak the largest
RMS relative displacement over the board; Steinberg's sin(pi x/a) sin(pi y/b) on a simply
supported board), with Steinberg's allowable for the board's peak, Z(r), beside it.
Displacements and curvatures are normal to the board (z), accelerations along the shaken axis.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fe.effective_mass import EffectiveMass, effective_mass, shortfall
from . import steinberg
from .base_excitation import BaseExcitation, base_excitation
from .damping import Damping, modal_damping
from .parts import PartVerdict, judged_parts, part_readers, shell_nodes
from .spectra import G, Psd, SineSweep, VibrationError, frequency_grid


@dataclass
class PartResult(PartVerdict):
    """Steinberg's check of one part (SI units; lives in hours, None where nothing moves); its
    margin z_allow / (3 z) - 1 is negative when it fails Steinberg's 2e7-cycle criterion."""

    z_rms_m: float
    z_allow_m: float
    z_allow_board_m: float | None
    ratio: float
    rate_hz: float
    life_h: float | None
    accel_rms_g: float
    curvature_rms_per_m: float
    damage: float | None = None
    sine_z_peak_m: float | None = None
    sine_damage: float | None = None

    @property
    def ok(self) -> bool:
        return self.ratio <= 1.0 and (self.damage or 0.0) < 1.0 and (self.sine_damage or 0.0) < 1.0


@dataclass
class Assessment:
    """Everything ``pcbdyn vibe`` reports, SI inside (see :meth:`to_dict` for the JSON)."""

    psd: Psd
    damping: Damping
    axis: str
    duration: float | None
    excitation: BaseExcitation
    damping_source: list
    parts: list
    node_z_rms: np.ndarray  # (n_nodes,) RMS relative displacement normal to the board [m], NaN off the shells
    grid: np.ndarray
    part_accel_psd: np.ndarray  # (n_grid, n_parts) absolute acceleration [(m/s^2)^2/Hz]
    part_z_psd: np.ndarray  # (n_grid, n_parts) relative displacement [m^2/Hz]
    effective_mass: EffectiveMass | None = None
    octave: dict | None = None
    sine: SineSweep | None = None
    notes: list = field(default_factory=list)

    @property
    def input_grms(self) -> float:
        return self.psd.grms() / G

    @property
    def z_peak_m(self) -> float:
        return float(np.nanmax(self.node_z_rms))

    def to_dict(self) -> dict:
        """The JSON contract: input_grms, modes[] (frequency_hz, damping_ratio, ...), parts[] (ref,
        z_rms_m, z_allow_m, ratio, life_h, ...) worst margin first, and the rest."""
        be = self.excitation
        return {
            "psd": {"name": self.psd.name, "source": self.psd.source,
                    "breakpoints": [{"frequency_hz": float(f), "psd_g2_hz": float(w / G**2)}
                                    for f, w in zip(self.psd.f, self.psd.w)]},
            "input_grms": self.input_grms,
            "axis": self.axis,
            "duration_s": self.duration,
            "damping": self.damping.describe(),
            "modes": [{"n": i + 1, "frequency_hz": float(f), "damping_ratio": float(z), "damping_source": s,
                       "effective_mass": m}
                      for i, (f, z, s, m) in enumerate(zip(be.frequencies, be.zeta, self.damping_source,
                                                           self._masses()))],
            "effective_mass_fraction": None if self.effective_mass is None else self.effective_mass.share(self.axis),
            "z_peak_rms_m": self.z_peak_m,
            "parts": [p.to_dict() for p in self.parts],
            "octave_rule": self.octave,
            "sine": None if self.sine is None else {"name": self.sine.name, "rate_oct_per_min": self.sine.rate,
                                                    "sweeps": self.sine.sweeps, "amplitude": self.sine.kind},
            "ok": all(p.ok for p in self.parts) and (self.octave is None or self.octave["ok"]),
            "notes": self.notes,
        }


    def _masses(self) -> list:
        """Each mode's effective masses (JSON), None per mode where they are not known."""
        if self.effective_mass is None:
            return [None] * len(self.excitation.frequencies)
        return self.effective_mass.as_dicts()


def _sine(be: BaseExcitation, sine: SineSweep, B: np.ndarray, parts, results) -> None:
    """Peak displacement and Miner damage of the sweep(s) at each part."""
    f = frequency_grid(sine.f[0], sine.f[-1], be.frequencies, be.zeta)
    z = np.abs(be.transfer(f) @ B.T) * sine.acceleration(f)[:, None]
    for j, res in enumerate(results):
        res.sine_z_peak_m = float(z[:, j].max())
        res.sine_damage = sine.sweeps * steinberg.sweep_damage(f, z[:, j], res.z_allow_m, sine.rate)


def board_excitation(board, bm, modes, K, M, damping: Damping, axis: str, probe_tol: float | None) -> tuple:
    """(:class:`BaseExcitation` of the solved board along ``axis`` with the modal damping asked for,
    where each mode's damping came from, the modes' :class:`~pcbdyn.fe.effective_mass.EffectiveMass`,
    notes: the shortfall when the modes carry < 90 % of the mass moved along ``axis``); a free board
    is refused naming its file."""
    zeta, source = modal_damping(damping, bm.model, modes, probe_tol)
    try:
        be = base_excitation(bm.model, modes, K, M, zeta, axis)
    except VibrationError as exc:
        raise VibrationError(f"{board.path.name}: {exc}") from None
    em = effective_mass(bm.model.nodes, M, modes.shapes)
    short = shortfall(em, axis, modes.frequencies)
    return be, source, em, [] if short is None else [f"{short} (the static residual adds it back, without resonance)"]


def assess(board, bm, modes, K, M, psd: Psd, damping: Damping, *, axis: str = "z", duration: float | None = None,
           sine: SineSweep | None = None, chassis_hz: float | None = None, parts=None,
           probe_tol: float | None = None) -> Assessment:
    """Judge the solved board model ``bm`` (``modes``, assembled ``K``, ``M``) under ``psd`` along
    ``axis``: RMS responses, Steinberg's check and life of every part (worst margin first), Miner
    damage over ``duration`` [s] and of ``sine``, and the octave rule against ``chassis_hz``.
    ``parts``: the :func:`~.parts.judged_parts` to judge (default: all of the board's);
    ``probe_tol`` [m]: how far off the board a test point of a UFF damping file may lie."""
    be, source, em, notes = board_excitation(board, bm, modes, K, M, damping, axis, probe_tol)
    octave = None if chassis_hz is None else steinberg.octave_rule(float(be.frequencies[0]), chassis_hz)
    return judge(board, bm.model, be, source, psd, damping, duration=duration, sine=sine, octave=octave, parts=parts,
                 masses=em, notes=notes)


def judge(board, model, be: BaseExcitation, source, psd: Psd, damping: Damping, *, duration: float | None = None,
          sine: SineSweep | None = None, octave: dict | None = None, parts=None, direction=None,
          masses: EffectiveMass | None = None, notes=()) -> Assessment:
    """The :class:`Assessment` of a board whose response to the base excitation is ``be`` on its own
    ``model`` (board frame: z normal to the board); ``direction``: the shaken axis in the board frame
    (default the excitation's own axis); ``source``: where each mode's damping came from;
    ``masses``: the modes' effective masses (None where the board is judged inside a larger structure)."""
    parts = judged_parts(board) if parts is None else parts
    axis = be.axis
    notes = list(notes)
    grid = frequency_grid(psd.f[0], psd.f[-1], be.frequencies, be.zeta)
    C0, C2 = be.covariance(psd, grid), be.covariance(psd, grid, moment=2)
    nodes = shell_nodes(model)
    node_z = np.full(model.nodes.shape[0], np.nan)
    node_z[nodes] = np.sqrt(be.variance(be.basis[6 * nodes + 2], C0))
    z_peak = float(np.nanmax(node_z))
    if be.frequencies[-1] < psd.f[-1]:
        notes.append(f"the modes found reach {be.frequencies[-1]:.0f} Hz, below the top of the spectrum "
                     f"({psd.f[-1]:.0f} Hz): the modes above respond statically only")
    results = []
    accel_psd, z_psd = np.zeros((grid.size, len(parts))), np.zeros((grid.size, len(parts)))
    if parts:
        read = part_readers(model, parts, axis, direction)
        Bz = be.columns(read["z"])
        Ba = be.columns(read["acceleration"], "acceleration")
        Ca = be.covariance(psd, grid, "acceleration")
        k_long, k_across = (np.sqrt(be.variance(be.columns(read[k]), C0)) for k in ("curvature_along", "curvature_across"))
        z_rms, m2 = np.sqrt(be.variance(Bz, C0)), be.variance(Bz, C2)
        a_rms = np.sqrt(be.variance(Ba, Ca))
        accel_psd, z_psd = be.response_psd(Ba, psd, grid, "acceleration"), be.response_psd(Bz, psd, grid)
        h = board.thickness
        for j, p in enumerate(parts):
            z_allow = steinberg.allowable_displacement(p.span, p.length, h, p.c)
            r = float(z_rms[j] / z_peak) if z_peak > 0 else 0.0
            rate = steinberg.zero_crossing_rate(z_rms[j] ** 2, m2[j])
            life = steinberg.random_life(z_rms[j], z_allow, rate)
            results.append(PartResult(
                p.ref, p.package, p.c, p.span, p.length, r, float(z_rms[j]), z_allow,
                steinberg.allowable_displacement(p.span, p.length, h, p.c, r) if r > 0 else None,
                3.0 * float(z_rms[j]) / z_allow, rate, None if np.isinf(life) else life / 3600.0,
                float(a_rms[j]) / G, float(max(k_long[j], k_across[j])),
                None if duration is None else (duration / life if np.isfinite(life) else 0.0)))
        if sine is not None:
            _sine(be, sine, Bz, parts, results)
    order = np.argsort([r.margin for r in results], kind="stable")
    return Assessment(psd, damping, axis, duration, be, source, [results[i] for i in order],
                      node_z, grid, accel_psd[:, order], z_psd[:, order], masses, octave, sine, notes)
