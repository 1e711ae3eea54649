"""A housing with its cards under a vibration specification: the base excitation enters at the housing's
supports, the whole system responds (its modes), and every part of every card is judged on the card's
own model (Steinberg's check, life, :func:`.assess.judge`) from the system's response seen in the card's
axes. The octave rule comes from the computed modes: a card's fundamental is the first mode most of
whose kinetic energy is the card's, the chassis resonance the first mode most of whose energy is the
housing's (unless the user states it)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import steinberg
from .assess import judge
from .base_excitation import AXES, BaseExcitation, base_excitation
from .damping import Damping, modal_damping
from .parts import judged_parts
from .spectra import Psd, SineSweep, VibrationError

#: a mode belongs to a part (a card, the housing) when the part holds at least this share of its energy
OWN_SHARE = 0.5


@dataclass
class SystemAssessment:
    """The verdict on every card (``cards``: {name: :class:`.assess.Assessment`}) of a system under one
    specification; ``chassis_hz``: the housing's resonance the octave rule takes (None: no mode is the
    housing's), ``stated``: given by the user rather than computed."""

    excitation: BaseExcitation
    cards: dict
    chassis_hz: float | None
    stated: bool

    def to_dict(self) -> dict:
        cards = {name: a.to_dict() for name, a in self.cards.items()}
        first = next(iter(cards.values()))
        return {"input_grms": first["input_grms"], "axis": first["axis"], "duration_s": first["duration_s"],
                "damping": first["damping"], "modes": first["modes"], "chassis_hz": self.chassis_hz,
                "chassis_source": "stated" if self.stated else "computed",
                "cards": {name: {k: v for k, v in c.items() if k not in ("modes", "psd")} for name, c in cards.items()},
                "ok": all(c["ok"] for c in cards.values())}


def first_mode_of(shares: np.ndarray, frequencies) -> float | None:
    """The frequency of the first mode whose share (a row of mode shares) is at least :data:`OWN_SHARE`."""
    own = np.flatnonzero(shares >= OWN_SHARE)
    return float(frequencies[own[0]]) if own.size else None


def card_parts(system, exclude=()) -> dict:
    """{card: its judged parts} leaving out ``exclude`` ("card.ref" each)."""
    out = {}
    bad = [e for e in exclude if e.split(".", 1)[0] not in system.cards or "." not in e]
    if bad:
        raise VibrationError(f"--exclude {', '.join(bad)}: give a card's part as <card>.<ref> (cards: "
                             f"{', '.join(system.cards)})")
    for name, pc in system.cards.items():
        mine = [e.split(".", 1)[1] for e in exclude if e.split(".", 1)[0] == name]
        out[name] = judged_parts(pc.card.board, mine)
    return out


def assess_system(system, modes, K, M, psd: Psd, damping: Damping, *, axis: str = "z", duration: float | None = None,
                  sine: SineSweep | None = None, chassis_hz: float | None = None, parts: dict | None = None,
                  probe_tol: float | None = None, zeta=None) -> SystemAssessment:
    """Judge every card of the solved system model ``system`` (``modes``, assembled ``K``, ``M``) shaken
    at the housing's supports along ``axis`` (``zeta``: modal damping ratios that replace ``damping``'s);
    ``parts``: {card: judged parts} (default :func:`card_parts`)."""
    if zeta is None:
        zeta, source = modal_damping(damping, system.model, modes, probe_tol)
    else:
        source = ["given"] * len(zeta)
    try:
        be = base_excitation(system.model, modes, K, M, zeta, axis)
    except VibrationError as exc:
        raise VibrationError(f"{system.box.path.name}: {exc}") from None
    shares = system.mode_shares(modes.shapes)
    labels = list(system.share_groups())
    housing = sum(shares[i] for i, n in enumerate(labels) if n not in system.cards)
    chassis = chassis_hz if chassis_hz is not None else first_mode_of(housing, modes.frequencies)
    parts = card_parts(system) if parts is None else parts
    cards = {}
    for name, pc in system.cards.items():
        f_card = first_mode_of(shares[labels.index(name)], modes.frequencies)
        octave = steinberg.octave_rule(f_card, chassis) if f_card is not None and chassis is not None else None
        direction = pc.card.R.T @ np.eye(3)[AXES.index(axis)]
        cards[name] = judge(pc.card.board, pc.local.model, be.seen_by(pc.nodes, pc.card.R), source, psd, damping,
                            duration=duration, sine=sine, octave=octave, parts=parts[name], direction=direction)
    return SystemAssessment(be, cards, chassis, chassis_hz is not None)
