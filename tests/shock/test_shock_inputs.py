"""Shock inputs: pulse texts, records and SRS files read with their units, and one clear message
for each bad input (a pulse without units, a negative duration, unsorted SRS frequencies, ...)."""

import numpy as np
import pytest

from pcbdyn.vibration.pulses import parse_pulse, read_history, read_srs
from pcbdyn.vibration.spectra import G, VibrationError


def test_pulses_in_any_units():
    hs = parse_pulse("half-sine 1500 g 0.5 ms")
    assert hs.kind == "half-sine" and hs.peak == pytest.approx(1500 * G) and hs.duration == pytest.approx(5e-4)
    # the chords' area (velocity change) is the sine's, 2 peak T / pi, within (pi/400)^2 / 12
    assert np.trapezoid(hs.a, hs.t) == pytest.approx(2 * 1500 * G * 5e-4 / np.pi, rel=1e-5)
    assert parse_pulse("HALF-SINE 14710 m/s^2 500us").peak == pytest.approx(14710.0)
    saw = parse_pulse("sawtooth 100g 6 ms")
    np.testing.assert_allclose(saw.t, [0, 6e-3, 6e-3])  # the terminal drop is a jump
    np.testing.assert_allclose(saw.a, [0, 100 * G, 0])
    trap = parse_pulse("trapezoid 50 g 11 ms rise 1 ms fall 2 ms")
    np.testing.assert_allclose(trap.t, [0, 1e-3, 9e-3, 11e-3])
    assert parse_pulse("trapezoid 50 g 10 ms").t[1] == pytest.approx(1e-3)  # 10 % rise and fall by default


@pytest.mark.parametrize("text, message", [
    ("half-sine 1500 0.5 ms", r"the peak '1500' has no unit; write it with one, e.g. '1500 g'"),
    ("half-sine 1500 g 0.5", r"the duration '0.5' has no unit; write it with one, e.g. '0.5 ms'"),
    ("half-sine 1500 g -0.5 ms", r"the duration -0.5 ms must be above 0"),
    ("half-sine 1500 kg 0.5 ms", r"the peak: '1500 kg' has unit 'kg' .*expected a unit like 'm/s\^2'"),
    ("square 10 g 1 ms", r"unknown shape 'square' \(half-sine, sawtooth, trapezoid\)"),
    ("half-sine 1500 g", r"expected a peak and a duration"),
    ("trapezoid 50 g 10 ms rise 6 ms", r"rise and fall \(12 ms\) exceed the duration \(10 ms\)"),
])
def test_bad_pulses_are_refused_clearly(text, message):
    with pytest.raises(VibrationError, match=rf"--pulse '{text}': {message}"):
        parse_pulse(text)


def test_records_and_spectra_read_with_units(tmp_path):
    (tmp_path / "rec.csv").write_text("# a comment\ntime [ms],acceleration [m/s^2]\n0,0\n0.1,5\n0.2,0\n")
    rec = read_history(tmp_path / "rec.csv")
    np.testing.assert_allclose(rec.t, [0, 1e-4, 2e-4])
    assert rec.peak == 5.0 and rec.kind == "history"
    (tmp_path / "srs.csv").write_text("frequency [kHz],acceleration [g]\n0.1,10\n1,1000\n10,1000\n")
    spec = read_srs(tmp_path / "srs.csv", 10.0)
    np.testing.assert_allclose(spec.f, [100, 1000, 10000])
    assert spec.at(np.array([316.2278]))[0] == pytest.approx(100 * G, rel=1e-5)  # log-log between breakpoints


@pytest.mark.parametrize("reader, text, message", [
    ("srs", "frequency [Hz],acceleration [g]\n100,10\n2000,1000\n1000,1000\n",
     r"data row 3: frequency 1000 Hz does not rise above the row before \(2000 Hz\); sort the rows"),
    ("srs", "frequency [Hz],acceleration\n100,10\n1000,1000\n", r"column 'acceleration' has no unit; write it as "
                                                                r"'acceleration \[g\]'"),
    ("history", "time [s],acceleration [g]\n0,0\n0.002,1\n0.001,0\n",
     r"data row 3: time 0.001 s does not rise above the row before \(0.002 s\); sort the rows by increasing time"),
    ("history", "time [s],accel [g]\n0,0\n1,1\n", r"no column 'acceleration'"),
])
def test_bad_files_are_refused_clearly(tmp_path, reader, text, message):
    path = tmp_path / "input.csv"
    path.write_text(text)
    with pytest.raises(VibrationError, match=rf"input.csv: {message}"):
        read_srs(path, 10.0) if reader == "srs" else read_history(path)
