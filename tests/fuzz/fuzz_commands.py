"""Mutated inputs run through the commands as a user runs them (click's CliRunner, in this process): a run
ends with exit 0 and a JSON whose every number is finite, or with exit 2 and one ``error:`` line that names
the input file; exit 3 (pcbdyn reporting a bug of its own), any other exit or an exception is a crash. Shared
by tests/fuzz/test_fuzz_commands.py and benchmarks/fuzz_long.py."""

from __future__ import annotations

import json
import shutil
import signal
import tomllib
from pathlib import Path

from fuzz_mutate import Source, dump_toml, mutate_csv, mutate_toml, mutate_uff
from fuzz_outcome import Outcome, not_finite

ROOT = Path(__file__).resolve().parents[2]
PLATE = ROOT / "examples" / "plain_plate"


def _reject_constant(name):
    raise ValueError(f"{name} in the JSON")


def run_command(kind: str, args, name: str, json_path: Path, invalid: bool, timeout: float = 120.0) -> Outcome:
    """The outcome of ``pcbdyn args`` on a mutated input named ``name`` (see the module notes)."""
    from click.testing import CliRunner

    from fuzz_outcome import _alarm, _Hang
    from pcbdyn.cli import main

    json_path.unlink(missing_ok=True)
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        r = CliRunner().invoke(main, [str(a) for a in args])
    except _Hang:
        return Outcome(kind, "hang", f"pcbdyn {' '.join(map(str, args))}: no answer within {timeout:g} s")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    if isinstance(r.exception, _Hang):
        return Outcome(kind, "hang", f"no answer within {timeout:g} s")
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("error:")]
    if r.exit_code == 2 and len(errors) == 1 and "Traceback" not in r.output:
        if name not in errors[0]:
            return Outcome(kind, "unnamed", errors[0][:500])
        return Outcome(kind, "clean", errors[0][:300])
    if r.exit_code == 2 and "Usage:" in r.output:  # a click usage error (a file the options name is bad)
        return Outcome(kind, "clean", r.output.strip().splitlines()[-1][:300])
    if r.exit_code != 0:
        return Outcome(kind, "crash", f"exit {r.exit_code}: {r.output[-1500:]}")
    if invalid:
        return Outcome(kind, "accepted", "an invalid input ran without an error")
    try:
        data = json.loads(json_path.read_text(), parse_constant=_reject_constant)
    except (OSError, ValueError) as exc:
        return Outcome(kind, "nan", f"the JSON: {exc}")
    bad = not_finite(data) or _null_frequencies(data)
    if bad:
        return Outcome(kind, "nan", bad)
    if data.get("modes") == [] and not data.get("warning"):
        return Outcome(kind, "accepted", "no mode in the band and no warning saying why")
    return Outcome(kind, "ok")


def _null_frequencies(data, where="json") -> str:
    """Where a frequency in the JSON is null or not above 0 (a NaN written as null)."""
    if isinstance(data, dict):
        for k, v in data.items():
            if ("frequency" in k or k.startswith("f_")) and isinstance(v, (int, float, type(None))) \
                    and not isinstance(v, bool) and (v is None or v <= 0) and k != "frequency_std_hz":
                return f"{where}.{k} = {v}"
            if bad := _null_frequencies(v, f"{where}.{k}"):
                return bad
    elif isinstance(data, list):
        for i, v in enumerate(data):
            if bad := _null_frequencies(v, f"{where}[{i}]"):
                return bad
    return ""


def small_plate(folder: Path) -> Path:
    """The plain plate example at a 6 mm mesh (fast), with its points, in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    text = (PLATE / "board.toml").read_text().replace('mesh_size = "2.5 mm"', 'mesh_size = "6 mm"')
    (folder / "board.toml").write_text(text)
    shutil.copy(PLATE / "points.csv", folder / "points.csv")
    return folder / "board.toml"


def simulated_test(folder: Path) -> tuple:
    """(test.uff, frequencies.csv) simulated on :func:`small_plate` (six modes, no noise)."""
    from click.testing import CliRunner

    from pcbdyn.cli import main
    from pcbdyn.testdata.measured import read_modes

    board = small_plate(folder)
    uff = folder / "test.uff"
    r = CliRunner().invoke(main, ["simulate-test", str(board), "--points", str(folder / "points.csv"), "--excite",
                                  "30,40", "--modes", "6", "--out", str(uff)])
    assert r.exit_code == 0, r.output
    f = read_modes(uff).frequencies
    (folder / "frequencies.csv").write_text("configuration,mode,frequency_hz\n"
                                            + "".join(f"base,{k + 1},{float(v) * 1.03!r}\n" for k, v in enumerate(f)))
    return uff, folder / "frequencies.csv"


def build_case(src: Source, seeds: Path, work: Path) -> Outcome:
    """``pcbdyn build`` of a mutated small plate."""
    doc, invalid = mutate_toml(tomllib.loads((seeds / "board.toml").read_text()), src, gentle=src.integer(0, 2) > 0)
    if src.integer(0, 3) == 0 and isinstance(doc.get("analysis"), dict):  # a band below the first mode (~110 Hz)
        doc["analysis"]["f_max"] = src.choice(["100 Hz", "1 Hz", "0.5 kHz"])
    board = work / "board.toml"
    board.write_bytes(dump_toml(doc))
    return run_command("build (command)", ["build", board, "--no-pictures", "--json", work / "out.json"], "board.toml",
                       work / "out.json", invalid)


def correlate_case(src: Source, seeds: Path, work: Path) -> Outcome:
    """``pcbdyn correlate`` of the small plate with a mutated test file."""
    text, invalid = mutate_uff((seeds / "test.uff").read_text(encoding="latin-1"), src)
    test = work / "test.uff"
    test.write_bytes(text.encode("latin-1", "replace"))
    return run_command("correlate (command)", ["correlate", seeds / "board.toml", test, "--json", work / "out.json"],
                       "test.uff", work / "out.json", invalid)


def update_case(src: Source, seeds: Path, work: Path) -> Outcome:
    """``pcbdyn update --frequencies`` of the small plate with a mutated table (two iterations at most)."""
    text = (seeds / "frequencies.csv").read_text()
    if src.integer(0, 1):  # measured frequencies off the model's by a few percent: the update has work to do
        head, *rows = text.splitlines()
        rows = [",".join(r.split(",")[:2] + [repr(float(r.split(",")[2]) * src.choice([0.9, 0.97, 1.02, 1.1]))])
                for r in rows]
        text, invalid = "\n".join([head, *rows]) + "\n", False
    else:
        text, invalid = mutate_csv(text, src, ("mode", "frequency_hz"), True)
    table = work / "frequencies.csv"
    table.write_text(text, encoding="utf-8", errors="surrogatepass")
    return run_command("update (command)", ["update", seeds / "board.toml", "--frequencies", table, "--max-iter", "2",
                                            "--out", work / "upd", "--force", "--json", work / "out.json"],
                       "frequencies.csv", work / "out.json", invalid)


CASES = {"build": build_case, "correlate": correlate_case, "update": update_case}
