"""Everything a test needs is in the repository: no file of the package or of the tests refers to the
project's folders beside the repository (reference data, the thesis, notes); only the third-party files
of ``../shared/realdata`` may be read, by tests that skip when that folder is absent (a user's clone)."""

import re
from pathlib import Path

import reference

ROOT = Path(__file__).resolve().parents[2]
#: what a fresh clone does not have beside it (spelt in pieces so that this file does not match itself)
OUTSIDE = re.compile("|".join([r"\.\./" + "shared/(?:reference|seed|notes)", "shared" + "/reference",
                               "PCBDYN_" + "REFERENCE"]))


def test_no_file_of_the_package_or_the_tests_refers_beside_the_repository():
    bad = [f"{f.relative_to(ROOT)}:{n}" for top in ("pcbdyn", "tests") for f in sorted((ROOT / top).rglob("*"))
           if f.is_file() and f.suffix in (".py", ".toml", ".json", ".md", ".csv", ".txt", ".cfg", ".ini")
           for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1) if OUTSIDE.search(line)]
    assert not bad


def test_the_reference_data_are_in_the_repository_with_their_sources():
    assert reference.REFERENCE_DIR.is_relative_to(ROOT)
    readme = (reference.REFERENCE_DIR / "README.md").read_text()
    assert "NAFEMS" in readme and "Leissa" in readme and "1999" in readme
    assert reference.load("plates.json")["nafems_square_plate"]["FV12_free_free_Hz_modes_4_to_9"][0] == 1.622
    assert reference.thesis_case("T5.3_cantilever_beam")["thesis"]
    assert "1999" in reference.load("thesis_tables.json")["source"]
