"""Perturbed configurations designed by ``pcbdyn pretest`` (issue 41) for the six-part card's six part
thicknesses: what is written is what was designed (the configurations built from the written file by
the board's own builder, a mass on its own node, carry the information the design predicted), and the
design holds more information than the thesis' own c2, c3. The simulation over 50 seeds is
benchmarks/bench_pretest_configs.py."""

from __future__ import annotations


from dataclasses import replace

import numpy as np
import pytest

from pcbdyn.board import load_board
from pcbdyn.problems.pretest import configuration_model, pretest_model
from pcbdyn.problems.pretest_configs import (configuration_entries, design_configurations, frequency_block,
                                             identifiability, write_configurations)
from pcbdyn.problems.pretest_points import read_candidates
from pcbdyn.updating import design
from pretest_cards import CARD, NAMES, six_thickness_card

SIGMA = 0.2 / 100 / np.sqrt(3)


def blocks_of(board, model, configs):
    out = []
    for c in configs:
        m = replace(configuration_model(board, c, NAMES), lam=model.lam, position=model.position)
        lam, phi = m.modes()
        out.append(frequency_block(lam, phi, m, m.dKs, m.dMs, SIGMA))
    return out


def test_designed_configurations_as_written_carry_the_predicted_information(tmp_path):
    board = load_board(six_thickness_card(tmp_path / "six.toml"))
    model = pretest_model(board, NAMES)
    cand = read_candidates(board, CARD / "points.csv")
    d = design_configurations(model, cand, [0.02, 0.0532], 2, 0.2, max_places=16)
    entries = configuration_entries(board, cand, d.chosen)
    written = load_board(write_configurations(board, entries, tmp_path / "designed.toml", load_board))
    assert written.configuration_names() == ["c2", "c3", "pretest1", "pretest2"]
    base = frequency_block(model.lam, model.phi, model, model.dKs, model.dMs, SIGMA)
    built = identifiability(model, [base] + blocks_of(written, model, ["pretest1", "pretest2"]))
    for n in NAMES:
        assert built["std_pct"][n] == pytest.approx(d.after["std_pct"][n], rel=0.01)
        assert d.after["std_pct"][n] < d.before["std_pct"][n]
    thesis = [base] + blocks_of(written, model, ["c2", "c3"])
    assert d.existing["std_pct"] == pytest.approx(identifiability(model, thesis)["std_pct"], rel=1e-9)
    designed = [base] + blocks_of(written, model, ["pretest1", "pretest2"])
    assert design.log_det(design.fisher(designed)) > design.log_det(design.fisher(thesis))
