"""One home for each concept (issue 45): the source is scanned for the concepts that once had two or
three homes, and for target names built by hand beside the one target grammar (``pcbdyn/targets.py``)."""

import ast
import re
from pathlib import Path

from pcbdyn import targets

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "pcbdyn"
#: first words of a target name: every target collection (``components.``, ``cards.``)
COLLECTIONS = sorted({c for c, _ in targets.KINDS} | set(targets.TABLES) | set(targets.NESTED))
#: last words of a target name (``.mass``, ``.k_rot``)
ATTRIBUTES = sorted({a for _, a in targets.KINDS})
STARTS = re.compile(r"^(?:%s)\.$" % "|".join(COLLECTIONS))
ENDS = re.compile(r"^\.(?:%s)$" % "|".join(ATTRIBUTES))


def sources():
    return sorted(PACKAGE.rglob("*.py"))


def text(pattern: str) -> list:
    """``file:line`` of every line of the package that matches ``pattern``."""
    rx = re.compile(pattern)
    return [f"{f.relative_to(ROOT)}:{n}" for f in sources()
            for n, line in enumerate(f.read_text().splitlines(), 1) if rx.search(line)]


def test_each_concept_has_one_home():
    assert [h.split(":")[0] for h in text(r"^\s*def solve_modes\(")] == ["pcbdyn/fe/modal.py"]
    assert [h.split(":")[0] for h in text(r"^\s*class Modes\b")] == ["pcbdyn/fe/modal.py"]
    assert [h.split(":")[0] for h in text(r"^\s*class MeasuredModes\b")] == ["pcbdyn/testdata/data.py"]
    assert [h.split(":")[0] for h in text(r"^\s*def mac\(|\.conj\(\)\.T @|\) \*\* 2 / np\.outer")] == [
        "pcbdyn/correlation/mac.py"] * 2  # the MAC (thesis eq. 2.3), the others call it
    assert [h.split(":")[0] for h in text(r"^\s*def \w*copy\w*\(")] == ["pcbdyn/fe/model.py"]
    assert [h.split(":")[0] for h in text(r"replace\(\w+, sets=|Model\([\w.]+\.nodes, ")] == ["pcbdyn/fe/model.py"]
    assert [h.split(":")[0] for h in text(r"^\s*def (?:add_noise|noisy_\w+|_perturb)\(")] == ["pcbdyn/testdata/noise.py"] * 4
    assert [h.split(":")[0] for h in text(r"\.uniform\(-1\.0, 1\.0")] == ["pcbdyn/testdata/noise.py"]
    assert [h.split(":")[0] for h in text(r"[\"']quad4[\"'], [\"']tri3[\"']|[\"']tri3[\"'], [\"']quad4[\"']")] == [
        "pcbdyn/fe/model.py"]  # SHELL_TYPES


def _built_target(node) -> bool:
    """An f-string or a concatenation that makes a target name from pieces: a collection's name followed
    by a value (``f"components.{ref}"``, ``"cards." + name``), or a value followed by an attribute
    (``f"{key}.mass"``). A field path of a reader's message (``f"{where}.mass"``: a place in the TOML
    file, named by ``where``) is no target."""
    if isinstance(node, ast.JoinedStr):
        parts = node.values
        for a, b in zip(parts, parts[1:]):
            if isinstance(a, ast.Constant) and isinstance(b, ast.FormattedValue) and STARTS.search(
                    re.split(r"[\s\"'(\[]", a.value)[-1]):
                return True
            if isinstance(a, ast.FormattedValue) and isinstance(b, ast.Constant) and ENDS.search(b.value) and not (
                    isinstance(a.value, ast.Name) and a.value.id == "where"):
                return True
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = node.left, node.right
        if isinstance(left, ast.Constant) and isinstance(left.value, str) and STARTS.search(left.value):
            return True
        if isinstance(right, ast.Constant) and isinstance(right.value, str) and ENDS.search(right.value):
            return True
    return False


def test_target_names_are_built_by_targets_only():
    """Every target name (``components.U1.mass``) and entry name (``components.U1``) is made by
    :func:`pcbdyn.targets.target`, :func:`~pcbdyn.targets.entry`, :func:`~pcbdyn.targets.member` or
    :func:`~pcbdyn.targets.prefix`: one grammar, spelt in one place."""
    bad = [f"{f.relative_to(ROOT)}:{node.lineno}" for f in sources() if f.name != "targets.py" or f.parent != PACKAGE
           for node in ast.walk(ast.parse(f.read_text())) if _built_target(node)]
    assert not bad


def test_the_scan_sees_a_target_built_by_hand():
    made = ['f"components.{c.ref}.mass"', 'f"{key}.k_rot"', '"cards." + name', 'key + ".thickness"', 'f"(fixtures.{n})"']
    kept = ['f"{where}.mass"', 'f"points.{i}"', 'f"effects.{name}"', '"board.E"', 'f"{stem}.json"']
    assert all(any(_built_target(n) for n in ast.walk(ast.parse(m))) for m in made)
    assert not any(_built_target(n) for k in kept for n in ast.walk(ast.parse(k)))


def _imported(path: Path) -> list:
    """The pcbdyn modules ``path`` imports (anywhere in it), as dotted names below ``pcbdyn``."""
    here = path.relative_to(ROOT).with_suffix("").parts[:-1]
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = list(here[:len(here) - node.level + 1]) if node.level else []
            out += [".".join(base + (node.module or "").split(".")).strip(".")]
            if not node.module:
                out += [".".join(base + [a.name]) for a in node.names]
        elif isinstance(node, ast.Import):
            out += [a.name for a in node.names]
    return [m for m in out if m.startswith("pcbdyn")]


def test_report_is_handed_plain_results():
    """report/ formats results; it knows no board, box, diagnosis or study (the layers of docs/design.md)."""
    banned = {"board", "box", "diagnosis", "problems"}
    bad = [f"{f.relative_to(ROOT)}: {m}" for f in sorted((PACKAGE / "report").rglob("*.py"))
           for m in _imported(f) if m.split(".")[1:2] and m.split(".")[1] in banned]
    assert not bad
    assert "pcbdyn.report.correlation_plots" in _imported(PACKAGE / "report" / "correlation_report.py")
    assert "pcbdyn.fe.effective_mass" in _imported(PACKAGE / "report" / "modes.py")


def test_report_saves_figures_one_way_and_shares_no_private_helper():
    """Figures are saved by :func:`pcbdyn.report.files.save_figure` only; a helper one report module lends
    another is public."""
    assert [h.split(":")[0] for h in text(r"\.savefig\(")] == ["pcbdyn/report/files.py"] * 2
    private = [f"{f.relative_to(ROOT)}:{node.lineno}" for f in sorted((PACKAGE / "report").rglob("*.py"))
               for node in ast.walk(ast.parse(f.read_text())) if isinstance(node, ast.ImportFrom) and node.level
               for a in node.names if a.name.startswith("_")]
    assert not private
