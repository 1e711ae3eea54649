"""Input spectra: bundled levels against their published overall RMS, CSV reading with units,
exact log-log integration against numerical quadrature, and clear errors for bad files."""

import numpy as np
import pytest
from scipy.integrate import quad

from pcbdyn.vibration.spectra import (G, NAMED_PSDS, Psd, VibrationError, load_psd, named_psd, read_psd_csv,
                                      read_sine_csv)


@pytest.mark.parametrize("name", sorted(NAMED_PSDS))
def test_bundled_levels_give_their_published_overall_grms(name):
    # GSFC-STD-7000 states 14.1, 10.0 and 6.8 grms for these breakpoints (rounded to 0.1 grms)
    stated = NAMED_PSDS[name][3]
    assert named_psd(name).grms() / G == pytest.approx(stated, abs=0.06)


def test_mean_square_is_the_integral_of_the_log_log_spectrum():
    psd = Psd("x", "", np.array([10.0, 40.0, 100.0, 300.0, 2000.0]), np.array([0.01, 0.04, 0.04, 0.004, 0.0004]))
    numeric = sum(quad(lambda lf: psd.at(np.exp(lf)) * np.exp(lf), np.log(a), np.log(b), epsrel=1e-12)[0]
                  for a, b in zip(psd.f[:-1], psd.f[1:]))
    assert psd.mean_square() == pytest.approx(numeric, rel=1e-9)  # the -3 dB/oct (n = -1) segment included
    assert psd.slopes[2] == pytest.approx(np.log(0.1) / np.log(3.0))
    assert psd.at([5.0, 2500.0]).tolist() == [0.0, 0.0]


def write(tmp_path, text, name="spec.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_in_g_and_in_si_units_read_alike(tmp_path):
    a = read_psd_csv(write(tmp_path, "frequency [Hz],psd [g^2/Hz]\n20,0.01\n80,0.04\n2000,0.04\n", "a.csv"))
    b = read_psd_csv(write(tmp_path, "# same spectrum in SI\nfrequency [kHz], psd [(m/s^2)^2/Hz]\n"
                                     f"0.02,{0.01 * G**2}\n0.08,{0.04 * G**2}\n2,{0.04 * G**2}\n", "b.csv"))
    np.testing.assert_allclose(a.f, b.f)
    np.testing.assert_allclose(a.w, b.w)
    assert load_psd(str(tmp_path / "a.csv")).name == "a"


@pytest.mark.parametrize("text, match", [
    ("frequency [Hz],psd [g^2/Hz]\n20,0.01\n10,0.02\n2000,0.02\n",
     r"spec.csv: data row 2: frequency 10 Hz does not rise above the row before \(20 Hz\); sort the rows"),
    ("frequency [Hz],psd [g^2/Hz]\n20,0.01\n80,-0.04\n",
     r"spec.csv: data row 2: PSD value -0.04 g\^2/Hz at 80 Hz must be above 0"),
    ("frequency [Hz],psd\n20,0.01\n80,0.04\n", r"spec.csv: column 'psd' has no unit; write it as 'psd \[g\^2/Hz\]'"),
    ("frequency [Hz],psd [mm]\n20,0.01\n80,0.04\n", r"spec.csv: column 'psd \[mm\]'.*expected a unit like"),
    ("freq [Hz],psd [g^2/Hz]\n20,0.01\n80,0.04\n", r"no column 'frequency'"),
    ("frequency [Hz],psd [g^2/Hz]\n20,0.01\n80,abc\n",
     r"data row 2: column 'psd \[g\^2/Hz\]' holds 'abc', not a number"),
    ("frequency [Hz],psd [g^2/Hz]\n20,0.01\n", r"at least two breakpoints"),
])
def test_bad_psd_files_get_clear_errors(tmp_path, text, match):
    with pytest.raises(VibrationError, match=match):
        read_psd_csv(write(tmp_path, text))


def test_unknown_psd_name_lists_the_bundled_ones():
    with pytest.raises(VibrationError, match="neither a CSV file nor a bundled spectrum; bundled: gevs-qual"):
        load_psd("gevs-qualification")


def test_sine_sweep_in_displacement_becomes_acceleration(tmp_path):
    s = read_sine_csv(write(tmp_path, "frequency [Hz],amplitude [mm]\n5,10\n20,10\n"), rate=2.0)
    assert s.kind == "displacement"
    assert s.acceleration([10.0])[0] == pytest.approx((2 * np.pi * 10) ** 2 * 0.01)
    g = read_sine_csv(write(tmp_path, "frequency [Hz],amplitude [g]\n20,2\n2000,2\n", "g.csv"), rate=1.0)
    assert g.kind == "acceleration" and g.acceleration([100.0])[0] == pytest.approx(2 * G)
