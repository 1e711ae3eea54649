"""The bundled examples hold inputs only: no run's output is kept among them (the six-part card carried
seven board.updated*.toml, so the README's update example wrote board.updated.8.toml), and no example
names a place to write beside itself (study.toml's ``out`` wrote examples/studies/study_out)."""

import tomllib
from pathlib import Path

from pcbdyn.commands.common import result_path
from pcbdyn.report.manifest import MANIFEST

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def test_no_example_holds_a_file_a_command_writes():
    files = [p for p in EXAMPLES.rglob("*") if p.is_file()]
    assert files and not [p for p in files if p.name == MANIFEST]
    for source in [p for p in files if p.suffix == ".toml"]:
        for suffix in ("updated", "diagnosed"):  # what update, wedgelock and diagnose write beside a board
            first = result_path(None, source, suffix)
            assert first == source.with_name(f"{source.stem}.{suffix}{source.suffix}"), first
            assert not list(source.parent.glob(f"{source.stem}.{suffix}.*")), source


def test_no_example_study_names_an_output_folder():
    for spec in EXAMPLES.rglob("*.toml"):
        study = tomllib.loads(spec.read_text()).get("study")
        assert study is None or "out" not in study, spec
