"""Success-ratio studies (thesis 5.3-5.4.4, 6.4.2) on the simulated free PCB of Tables 5.10-5.11:
42 element thicknesses, errors on elements 11, 13, 23 and 25 (3.0 -> 3.2 mm)."""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.updating import tls_qrf
from pcbdyn.problems.cases import SimulatedFreePCB
from pcbdyn.testdata import add_noise
from pcbdyn.updating.study import compress, localise, run_study, summarise
from pcbdyn.updating.weighting import tls_column_weight, tls_column_weight_from_noise

from reference import thesis_case

REF = thesis_case("T5.11_simulated_pcb")


@pytest.fixture(scope="module")
def pcb():
    return SimulatedFreePCB()


def test_case_is_the_thesis_board(pcb):
    """Parameters, true errors and free-free frequencies of Table 5.11. The README allows 4 % for
    a converged plate; this is the thesis' own 42-shell mesh, Guyan-condensed onto w (its mode 7
    comes out 4.3 % low), so 5 %."""
    assert pcb.n_params == 42
    changed = {f"t{k}" for k, v in REF["inputs"]["thickness_mm"]["px"].items()
               if v != REF["inputs"]["thickness_mm"]["pa"].get(k, REF["inputs"]["t_base_m"] * 1e3)}
    assert {pcb.parameter_names[i] for i in pcb.true_errors} == changed == {"t11", "t13", "t23", "t25"}
    for cfg_key, row in (("f_a", "free_FE_model(pa)"), ("f_x", "free_Experimental(px)")):
        f = pcb.configs[0][cfg_key]
        assert np.max(np.abs(f / np.array(REF["thesis"][row]) - 1)) < 0.05
    # the 10 g perturbation lowers every frequency (thesis Fig. 6.4)
    assert np.all(pcb.configs[1]["f_x"] < pcb.configs[0]["f_x"])


def test_noise_free_qms_localises_the_four_thicknesses(pcb):
    """Thesis Fig. 5.42: noise-free QMS with the first 7 modes, success ratio 100 %."""
    A, b = pcb.equations("qms", 0.0, np.random.default_rng(0))
    assert A.shape == (7 * 56, 42)  # thesis: 392 x 42
    for rank in (None, -1):
        sel = localise("tls-qrf", A, b, rank)
        assert [pcb.parameter_names[i] for i in sel] == ["t11", "t13", "t23", "t25"]
    loc = tls_qrf(A, b)
    # first-order change of a thickness entering bending as t^3: about the true +6.7 %
    assert np.all((loc.x[pcb.true_errors] > 0.05) & (loc.x[pcb.true_errors] < 0.09))
    assert loc.explains_data


def test_compression_keeps_every_method_result(pcb):
    rng = np.random.default_rng(3)
    A, b = pcb.equations("frf", 1.0, rng)
    Ac, bc = compress(A, b)
    assert Ac.shape == (43, 42)
    for method in ("tls-qrf", "svd-qr", "min-norm", "qr"):
        assert np.array_equal(localise(method, A, b), localise(method, Ac, bc)), method


def test_qms_one_percent_automatic_rank_is_full_and_equal_precision_tls_is_min_norm(pcb):
    """Why the study weighs b by the stated noise: the epsilon-condition curve of these QMS
    equations has no jump (largest step sigma_r/sigma_r+1 about 1.4, k2(A) about 42 where the
    thesis' Fig. 5.42a shows about 150), so n1 = n = 42. With eq. 4.43's t_b for k_A = k_b the
    out-of-range part of b (about half of ||b|| at 1 % noise) stays in the leading TLS subspace of
    C = [A, t_b b], the backward exclusion (5.55-5.62) keeps every parameter and TLS/QR-F is the
    thresholded LS solution (eq. 5.64), the minimum-norm method."""
    for shot in range(3):
        A, b = compress(*pcb.equations("qms", 1.0, np.random.default_rng([0, 0, 10**6, shot])))
        s = np.linalg.svd(A, compute_uv=False)
        assert np.max(s[:-1] / s[1:]) < 2.0
        loc = tls_qrf(A, b)
        assert loc.rank == 42 and loc.retained.size == 42
        assert loc.out_of_range > 0.3
        assert np.array_equal(loc.selected, localise("min-norm", A, b))


def test_noise_weight_measures_the_error_of_each_column(pcb):
    """The TLS weight from redrawn noise (eq. 4.43 with measured k_A, k_b) balances the error of b
    against that of one column of A: on QMS at 1 % it is far below eq. 4.43's k_A = k_b value,
    as the thesis expects ("data in A more precise"), and it is None without noise."""
    rng = np.random.default_rng(5)
    data = pcb.measure("qms", 1.0, rng)
    A, b = pcb.build("qms", data)
    redraws = [pcb.build("qms", tuple(add_noise(d, 1.0, rng) for d in data)) for _ in range(3)]
    t = tls_column_weight_from_noise(A, b, redraws)
    dA = np.mean([np.linalg.norm(Ad - A) for Ad, _ in redraws]) / np.sqrt(A.shape[1])
    db = np.mean([np.linalg.norm(bd - b) for _, bd in redraws])
    assert t == pytest.approx(dA / db, rel=0.1)
    assert t < 0.1 * tls_column_weight(A, b)
    assert tls_column_weight_from_noise(A, b, [(A, b)]) is None


@pytest.mark.parametrize("level", [0.5, 1.0])
def test_qms_tls_qrf_better_than_svd_qr_and_min_norm(pcb, level):
    """Issue 6 / thesis Fig. 5.44, automatic rank, 20 shots: with b weighted by the stated noise
    TLS/QR-F detects more of the four thicknesses than SVD/QR and the minimum-norm solution
    (which tie: SVD/QR keeps all 42 at full rank). Measured: 97.3 vs 88.5 % at 0.5 %, 47.9 vs
    44.9 % at 1 % (over 3 x 100 shots at 1 %: +3.4 +- 0.9 points, paired)."""
    s = summarise(run_study(pcb, [level], 20, ("tls-qrf", "svd-qr", "min-norm"), ("qms",), workers=1,
                            progress=False)).set_index("method")["mean"]
    assert s["tls-qrf"] > s["svd-qr"] and s["tls-qrf"] > s["min-norm"]


@pytest.mark.xfail(strict=True, reason="not reproduced (thesis rank n1 = n - 1 = 41): at 1 % over 20 shots "
                   "TLS/QR-F 42.9, SVD/QR 45.8, min-norm 44.9 %. Our QMS equations have no near-null direction "
                   "(sigma_42 / sigma_41 = 0.73, k2(A) = 42 vs about 150 in Fig. 5.42a), so cutting one "
                   "singular value drops information rather than noise, and 1 % shape noise (eq. 5.73) is "
                   "56 % of ||b|| (E_u >> E_x, eq. 5.71)")
def test_qms_one_percent_with_the_thesis_rank(pcb):
    s = summarise(run_study(pcb, [1.0], 20, ("tls-qrf", "svd-qr", "min-norm"), ("qms",), rank=-1, workers=1,
                            progress=False)).set_index("method")["mean"]
    assert s["tls-qrf"] >= s["svd-qr"] and s["tls-qrf"] >= s["min-norm"]


def test_pbc_raises_the_success_ratio(pcb):
    """Thesis 6.4.2 / Fig. 6.5: FRF output equations at 2 % noise; adding the configuration with
    10 g at node 56 raises the mean success ratio of TLS/QR-F."""
    s = summarise(run_study(pcb, [2.0], 40, ("tls-qrf",), ("frf", "frf+pbc"), workers=2, progress=False))
    m = s.set_index("equations")["mean"]
    assert m["frf+pbc"] > m["frf"]


def test_study_independent_of_workers_and_statistics(pcb):
    kw = dict(levels=[0.0, 0.5], shots=3, methods=("tls-qrf", "min-norm"), kinds=("qms",), progress=False)
    one, two = run_study(pcb, workers=1, **kw), run_study(pcb, workers=2, **kw)
    assert one.equals(two)
    assert len(one) == 2 * 3 * 2
    s = summarise(one)
    g = one[(one.method == "tls-qrf") & (one.level_pct == 0.5)]["success_ratio"]
    row = s[(s.method == "tls-qrf") & (s.level_pct == 0.5)].iloc[0]
    assert row["mean"] == pytest.approx(g.mean()) and row["std"] == pytest.approx(g.std(ddof=1))
    assert set(s[s.level_pct == 0.0]["mean"]) == {100.0}
    with pytest.raises(ValueError, match="methods"):
        run_study(pcb, [0.0], 1, ("magic",), progress=False)


def test_study_command(tmp_path):
    from pcbdyn.cli import main

    toml = tmp_path / "study.toml"
    toml.write_text('[study]\nlevels_pct = [0, 0.5]\nshots = 2\nmethods = ["tls-qrf", "svd-qr"]\n'
                    'workers = 1\n[case]\nerrors_mm = { "23" = 3.4 }\n')
    res = CliRunner().invoke(main, ["study", str(toml), "--json", str(tmp_path / "s.json"), "--quiet",
                                    "--out", str(tmp_path / "res")])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "s.json").read_text())
    assert data["true_errors"] == ["t23"]
    zero = [r for r in data["summary"] if r["level_pct"] == 0.0 and r["method"] == "tls-qrf"]
    assert zero[0]["mean"] == 100.0
    assert (tmp_path / "res" / "success_ratios.png").stat().st_size > 1000
    toml.write_text('[study]\nshots = 0\n')
    res = CliRunner().invoke(main, ["study", str(toml)])
    assert res.exit_code == 2 and "shots" in res.output


CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"


def _thicker_pgas(tmp_path, extra: str = ""):
    """model.toml (the card) and true.toml (its two PGAs 4.5 mm instead of 3.5 mm, no parameters,
    ``extra`` TOML appended) in ``tmp_path``."""
    import re

    text = (CARD / "board.toml").read_text()
    (tmp_path / "model.toml").write_text(text)
    for ref in ("U1", "U6"):
        text, n = re.subn(rf'(ref = "{ref}"\npackage = "PGA"\nat = \[[^\]]*\]\n)', r'\1thickness = "4.5 mm"\n', text)
        assert n == 1
    (tmp_path / "true.toml").write_text(re.sub(r"\[\[parameters\]\]\n(?:.+\n)+\n?", "", text) + extra)


def _simulate(tmp_path, name, *noise):
    from pcbdyn.cli import main

    res = CliRunner().invoke(main, ["simulate-test", str(tmp_path / "true.toml"), "--points", str(CARD / "points.csv"),
                                    "--excite", "135,63.57", "--df", "5", *noise, "--out", str(tmp_path / name)])
    assert res.exit_code == 0, res.output


def test_localize_command_finds_the_thicker_pgas(tmp_path):
    """The six-part card whose two PGAs are 4.5 mm instead of the model's 3.5 mm: from a
    noise-free simulated test, TLS/QR-F (QMS) selects t_PGA alone with a thickening, and the FBM
    map peaks inside a PGA footprint (40 x 40 mm at (40.5, 38.14) and (94.5, 139.86) mm)."""
    from pcbdyn.cli import main

    _thicker_pgas(tmp_path)
    _simulate(tmp_path, "true.uff")
    run = CliRunner().invoke
    res = run(main, ["localize", str(tmp_path / "model.toml"), str(tmp_path / "true.uff"), "--out",
                     str(tmp_path / "loc"), "--json", str(tmp_path / "loc.json")])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "loc.json").read_text())
    assert data["selected"] == ["t_PGA"] and data["order"][0] == "t_PGA"
    assert data["descending_ratio"][0] > 80
    assert 0.15 < data["solution"]["t_PGA"] < 0.5  # true +28.6 %, first-order estimate
    assert data["explains_data"] and data["rank"] == 4
    x, y = data["fbm_peak_mm"]
    assert any(abs(x - cx) <= 20 and abs(y - cy) <= 20 for cx, cy in ((40.5, 38.14), (94.5, 139.86)))
    assert (tmp_path / "loc" / "localisation.png").stat().st_size > 1000
    res = run(main, ["localize", str(tmp_path / "model.toml"), str(tmp_path / "true.uff"),
                     f"c9={tmp_path / 'true.uff'}"])
    assert res.exit_code == 2 and "c9" in res.output


def test_localize_with_the_stated_noise_tells_noise_from_a_missing_effect(tmp_path):
    """2 % shape noise (eq. 5.73) leaves a quarter of b outside range(A): without the noise stated
    the 5.2.3 check cries wolf; with ``--noise`` b is weighted for TLS by the errors that noise
    makes and judged against them, so the thicker PGAs are explained (t_PGA alone), while a 30 g
    mass the model lacks still is not."""
    from pcbdyn.cli import main

    noise = ("--noise", "f=0.2,shape=2")
    _thicker_pgas(tmp_path, '\n[[masses]]\nname = "hidden"\nat = ["120 mm", "150 mm"]\nmass = "30 g"\n')
    _simulate(tmp_path, "mass.uff", *noise, "--seed", "1")
    _thicker_pgas(tmp_path)
    _simulate(tmp_path, "noisy.uff", *noise, "--seed", "1")
    out = {}
    for name, stated in (("noisy", ()), ("noisy", noise), ("mass", noise)):
        js = tmp_path / f"{name}{len(stated)}.json"
        res = CliRunner().invoke(main, ["localize", str(tmp_path / "model.toml"), str(tmp_path / f"{name}.uff"), *stated,
                                        "--json", str(js)])
        assert res.exit_code == 0, res.output
        out[name, bool(stated)] = json.loads(js.read_text())
    plain, stated, lacking = out["noisy", False], out["noisy", True], out["mass", True]
    assert plain["tls_weight"] is None and not plain["explains_data"]
    assert stated["tls_weight"] > 0 and stated["explains_data"] and stated["selected"] == ["t_PGA"]
    assert stated["out_of_range_pct"] == pytest.approx(plain["out_of_range_pct"])
    assert not lacking["explains_data"] and lacking["out_of_range_pct"] > 2 * lacking["explain_tol_pct"]


def test_board_study_command(tmp_path):
    """A study on a board.toml (examples/studies/board_study.toml, fewer shots): the PGA
    thickness error is found at 100 % from noise-free QMS data and the JSON names it."""
    from pcbdyn.cli import main

    example = Path(__file__).resolve().parents[2] / "examples" / "studies" / "board_study.toml"
    text = example.read_text().replace("../six_part_card/", f"{CARD}/").replace("shots = 20", "shots = 2")
    text = text.replace("levels_pct = [0, 1, 2, 5]", "levels_pct = [0, 1]").replace('equations = ["qms", "fbm"]',
                                                                                   'equations = ["qms"]')
    (tmp_path / "study.toml").write_text(text.replace("[truth]", "workers = 1\n\n[truth]"))
    res = CliRunner().invoke(main, ["study", str(tmp_path / "study.toml"), "--json", str(tmp_path / "s.json"),
                                    "--quiet", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["pcbdyn-manifest.json", "shots.csv",
                                                                     "success_ratios.png", "summary.csv"]
    data = json.loads((tmp_path / "s.json").read_text())
    assert data["true_errors"] == ["t_PGA"]
    assert {r["method"]: r["mean"] for r in data["summary"] if r["level_pct"] == 0.0}["tls-qrf"] == 100.0
    (tmp_path / "bad.toml").write_text(text.replace('t_PGA = "4.5 mm"', 't_XYZ = "4.5 mm"'))
    res = CliRunner().invoke(main, ["study", str(tmp_path / "bad.toml")])
    assert res.exit_code == 2 and "t_XYZ" in res.output
