"""Shock response of a board through its fixtures against Navier's simply supported plate: a
half-sine by modal transient response (each Navier mode integrated in closed form), a shock
response spectrum by combined modal peaks, the same pulse given as a record sampled at 20 kHz,
and a free board refused."""

import numpy as np
import pytest
from closed_form import half_sine_response, maximax
from vibe_plates import A, B, navier, solve, write_free_plate, write_plate

from pcbdyn.vibration import parse_damping
from pcbdyn.vibration.pulses import SrsSpec, parse_pulse, read_history
from pcbdyn.vibration.shock import assess_shock
from pcbdyn.vibration.spectra import G, VibrationError

T, PEAK, ZETA = 0.5e-3, 1500 * G, 0.05
PARTS = [("U1", A * 500, B * 500), ("U2", A * 250, B * 250)]


def term(m: int, n: int, x: float = 0.5, y: float = 0.5) -> float:
    """phi_mn Gamma_mn of the mass-normalised Navier mode at (x A, y B): 16 sin(m pi x) sin(n pi y) / (m n pi^2)."""
    return 16 * np.sin(m * np.pi * x) * np.sin(n * np.pi * y) / (m * n * np.pi**2)


ODD = range(1, 60, 2)


def navier_peak(x: float, y: float) -> tuple:
    """(peak |u|, its time) at (x A, y B) under the half-sine: the sum over Navier modes (m, n odd to
    59) of phi Gamma z_mn(t), each z_mn the closed-form half-sine response of its oscillator."""
    resp = [(term(m, n, x, y), half_sine_response(navier(m, n), ZETA, PEAK, T)) for m in ODD for n in ODD]

    def u(t):
        return sum(c * r(t)[0] for c, r in resp)

    return maximax(u, T + 2 / navier(1, 1), 4000)


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """The 160 x 100 x 1.6 mm plate at 5 mm with a negligible part at the centre (U1) and one at the
    quarter/quarter point (U2); modes to 20 kHz (10 / T, as ``pcbdyn shock`` takes them)."""
    return solve(write_plate(tmp_path_factory.mktemp("shock"), 5.0, PARTS), 10.0 / T)


@pytest.fixture(scope="module")
def pulse_run(plate):
    board, bm, modes, K, M = plate
    return assess_shock(board, bm, modes, K, M, parse_pulse("half-sine 1500 g 0.5 ms"), parse_damping("zeta=0.05"))


def test_centre_of_a_simply_supported_plate_follows_navier_modes(pulse_run):
    """1500 g 0.5 ms half-sine, 5 % damping: the part at the centre (and the one at the quarter
    point) against Navier's modal time-history sum. Measured 0.08 % apart at the centre (FE
    frequencies 0.1 % low at 5 mm); the acceptance is 2 %."""
    ref, t_ref = navier_peak(0.5, 0.5)
    centre = next(p for p in pulse_run.parts if p.ref == "U1")
    assert centre.z_peak_m == pytest.approx(ref, rel=0.02)
    assert abs(centre.z_peak_m / ref - 1) < 0.003
    assert centre.t_peak_s == pytest.approx(t_ref, abs=2e-6)  # after the pulse: the first swing of mode (1, 1)
    assert pulse_run.z_peak_m == pytest.approx(centre.z_peak_m, rel=0.01)  # the centre moves most
    assert pulse_run.parts[0].ref == "U1"  # worst margin first
    assert centre.ratio == pytest.approx(centre.z_peak_m / centre.z_allow_m)
    quarter = next(p for p in pulse_run.parts if p.ref == "U2")
    assert quarter.z_peak_m == pytest.approx(navier_peak(0.25, 0.25)[0], rel=0.02)
    # higher modes add more at the quarter point than the (1, 1) shape's sin(pi/4)^2 = 0.5 says: the
    # position factor is read from the response, not assumed
    assert quarter.position_factor == pytest.approx(quarter.z_peak_m / centre.z_peak_m, rel=0.01)


def test_srs_input_combines_navier_modal_peaks(plate):
    """A flat-then-rising SRS: the centre's SRSS and ABS combinations of |phi Gamma| S(f_mn) / w_mn^2
    over Navier's modes to 20 kHz, the modes above taking the zero-period acceleration statically
    (their sum is the static deflection of the plate under the ZPA minus the modes' own)."""
    board, bm, modes, K, M = plate
    spec = SrsSpec("test", "", np.array([100.0, 2000.0, 20000.0]), np.array([50.0, 1000.0, 1000.0]) * G, 10.0)
    kept = [(m, n) for m in range(1, 400, 2) for n in range(1, 400, 2) if navier(m, n) <= modes.frequencies[-1]]
    left = [(m, n) for m in range(1, 400, 2) for n in range(1, 400, 2) if navier(m, n) > modes.frequencies[-1]]
    terms = [term(m, n) * spec.at(navier(m, n)) / (2 * np.pi * navier(m, n)) ** 2 for m, n in kept]
    residual = sum(term(m, n) / (2 * np.pi * navier(m, n)) ** 2 for m, n in left) * spec.value[-1]
    for rule, ref in (("srss", np.sqrt(np.sum(np.square(terms)) + residual**2)),
                      ("abs", np.sum(np.abs(terms)) + abs(residual))):
        s = assess_shock(board, bm, modes, K, M, spec, parse_damping("zeta=0.05"), combination=rule)
        centre = next(p for p in s.parts if p.ref == "U1")
        assert centre.z_peak_m == pytest.approx(ref, rel=0.02), rule
        assert centre.t_peak_s is None and s.combination == rule
    assert s.to_dict()["srs"]["value"][0] == pytest.approx(50.0)  # an SRS input is its own SRS


def test_a_record_of_the_pulse_sampled_at_20_khz_gives_the_pulses_answer(plate, pulse_run, tmp_path):
    """The half-sine sampled at 20 kHz (11 samples, time in ms): every peak within 1 % of the
    pulse's. Measured 0.82 % low: the record is read as chords between samples, whose area (the
    velocity change that drives this impulsive response, f1 T = 0.18) is short of the sine's by
    1 - (pi/10) cot(pi/20) / 2 = 0.82 %; the SRS within 0.9 % up to 10 kHz."""
    board, bm, modes, K, M = plate
    t = np.arange(11) / 20000.0
    rows = "".join(f"{x * 1e3:.6f},{1500 * np.sin(np.pi * x / T):.9f}\n" for x in t)
    (tmp_path / "record.csv").write_text("time [ms],acceleration [g]\n" + rows)
    rec = assess_shock(board, bm, modes, K, M, read_history(tmp_path / "record.csv"), parse_damping("zeta=0.05"))
    chord = 1 - (np.pi / 10) / np.tan(np.pi / 20) / 2
    for p, q in zip(pulse_run.parts, rec.parts):
        assert p.ref == q.ref
        for key in ("z_peak_m", "accel_peak_g", "curvature_peak_1pm"):
            assert getattr(q, key) == pytest.approx(getattr(p, key), rel=0.01), key
        assert q.z_peak_m / p.z_peak_m - 1 == pytest.approx(-chord, abs=5e-4)
        assert q.t_peak_s == pytest.approx(p.t_peak_s, abs=2e-6)
    np.testing.assert_allclose(rec.srs_value, pulse_run.srs_value, rtol=0.01)


def test_the_json_contract(pulse_run):
    d = pulse_run.to_dict()
    assert d["input"]["kind"] == "half-sine" and d["input"]["peak"] == pytest.approx(1500.0)
    assert d["input"]["duration"] == pytest.approx(T)
    for m in d["modes"]:
        assert {"frequency_hz", "damping_ratio", "participation"} <= set(m) and m["damping_ratio"] == ZETA
    # Gamma_11 = 8 sqrt(rho h a b) / pi^2 for the mass-normalised (1, 1) mode
    rho_h_ab = 1850.0 * 1.6e-3 * A * B
    assert abs(d["modes"][0]["participation"]) == pytest.approx(8 * np.sqrt(rho_h_ab) / np.pi**2, rel=0.01)
    for p in d["parts"]:
        assert {"ref", "z_peak_m", "curvature_peak_1pm", "z_allow_m", "ratio", "t_peak_s"} <= set(p)
    assert len(d["srs"]["frequency"]) == len(d["srs"]["value"]) == 121


def test_free_board_is_refused(tmp_path):
    board, bm, modes, K, M = solve(write_free_plate(tmp_path), 2000.0)
    with pytest.raises(VibrationError, match=r"free.toml: the model is free .*declare how the board is held in "
                                             r"\[\[fixtures\]\]"):
        assess_shock(board, bm, modes, K, M, parse_pulse("half-sine 100 g 1 ms"), parse_damping(None), parts=[])
