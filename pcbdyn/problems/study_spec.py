"""A success-ratio study's file (study.toml, format in :mod:`pcbdyn.commands.study`): its [study], [case]
and [truth] tables read and checked once, and the case they describe built (:mod:`.cases`)."""

from __future__ import annotations

from pathlib import Path

from ..domain import StructureError
from ..inputs import MAX_NAME, Reader, read_toml
from ..units import shown
from .cases import CASES, CaseError, StructureCase

KEYS = ["case", "levels_pct", "shots", "methods", "equations", "rank", "seed", "workers", "scheduler", "board",
        "points"]


class StudyError(StructureError):
    """A study.toml that cannot be used; the message names the file, the field and the fix."""


def read_spec(path: Path) -> dict:
    """The [study], [case] and [truth] tables of ``path``, every field checked (type, range, files);
    a StudyError names the file, the field and the fix."""
    from ..updating.study import METHODS

    doc = read_toml(path, StudyError)[1]
    r = Reader(path, StudyError)
    r.table(doc, "top level", ["study", "case", "truth"], required=["study"])
    if isinstance(doc["study"], dict) and "out" in doc["study"]:
        r.fail("study.out", "the output folder is given as every command's is: remove out from [study] and run "
                            "'pcbdyn study FILE --out DIR'")
    s = r.table(doc["study"], "study", KEYS)
    case = s.get("case", "simulated_free_pcb")
    if not isinstance(case, str) or case not in CASES:
        r.fail("study.case", f"{shown(case)} is not a case; choose one of {sorted(CASES)}")
    levels = _numbers(r, s.get("levels_pct", [0, 0.5, 1, 2]), "study.levels_pct", 0.0, 100.0,
                      "a list of noise levels in %, from 0 to 100, e.g. [0, 0.5, 1, 2]")
    shots = r.whole(s.get("shots", 20), "study.shots", 1, 100_000, "the thesis uses 20")
    methods = _choices(r, s.get("methods", ["tls-qrf", "svd-qr", "min-norm"]), "study.methods", list(METHODS))
    equations = _choices(r, s.get("equations", ["qms"]), "study.equations", list(CASES[case].kinds))
    rank = s.get("rank")
    if rank is not None:
        r.whole(rank, "study.rank", -10_000, 10_000, "k, or -k for n_params - k; omit it for automatic")
    seed = r.whole(s.get("seed", 0), "study.seed", 0, 2**63 - 1, "any whole number from 0")
    workers = None if s.get("workers") is None else r.whole(s["workers"], "study.workers", 1, 1024, "e.g. 2")
    scheduler = None if s.get("scheduler") is None else r.text(s["scheduler"], "study.scheduler", 200)
    opts = _case_options(r, doc, CASES[case].options)
    if CASES[case] is StructureCase:
        files = {key: _file(r, path, s, key) for key in ("board", "points")}
        structure = _structure(r, files["board"])
        opts.update(structure=structure, points_csv=files["points"], truth=_truth(r, doc, structure, opts))
    elif "truth" in doc or "board" in s or "points" in s:
        r.fail("study.board" if "board" in s else "study.points" if "points" in s else "truth",
               f"only case = \"board\" takes a board, points and a [truth] table (case is {case!r})")
    return {
        "case": case, "case_options": opts, "levels": levels, "shots": shots, "methods": methods,
        "equations": equations, "rank": rank, "seed": seed, "workers": workers, "scheduler": scheduler,
    }


def build_case(path: Path, spec: dict):
    """The case of ``spec`` (:func:`read_spec` of ``path``); a StudyError naming the file when its
    options cannot be used."""
    try:
        return CASES[spec["case"]](**spec["case_options"])
    except CaseError as exc:
        raise StudyError(f"{Path(path).name}: {exc}") from None


def _case_options(r, doc: dict, options: dict) -> dict:
    """The [case] table checked against a case's ``options`` (see :attr:`.cases.SimulatedFreePCB.options`)."""
    opts = dict(r.table(doc.get("case", {}), "case", sorted(options)))
    for key, kind in options.items():
        if key not in opts:
            continue
        where = f"case.{key}"
        if kind == "names":
            opts[key] = [r.text(v, f"{where}[{i}]", MAX_NAME) for i, v in enumerate(r.list(opts, key, where))]
        elif kind == "elements":
            table = r.table(opts[key], where)
            if not all(k.isdigit() and len(k) < 6 for k in table):
                r.fail(where, "keys are element numbers, e.g. { \"11\" = 3.2, \"13\" = 3.2 }")
            opts[key] = {int(k): r.number(v, f"{where}.{k}", 0.0, 1000.0) for k, v in table.items()}
        elif kind[0] is int:
            opts[key] = r.whole(opts[key], where, kind[1], kind[2])
        else:
            opts[key] = r.number_in(opts[key], where, kind[1], kind[2])
    return opts


def _structure(r, board: Path):
    """The structure of ``board`` (board.toml, box.toml), its errors named as study.board's."""
    from .load import load_structure

    try:
        return load_structure(board)
    except StructureError as exc:
        r.fail("study.board", str(exc))


def _truth(r, doc: dict, structure, opts: dict) -> dict:
    """The [truth] of a board study: {parameter of the structure (of ``params`` when given): SI value}."""
    params = {p.name: p for p in structure.parameters}
    unknown = [n for n in opts.get("params", []) if n not in params]
    if unknown:
        r.fail("case.params", f"{shown(unknown[0])} is not a parameter of {structure.path.name} "
                              f"(known: {', '.join(params)})")
    truth = r.table(doc.get("truth", {}), "truth", list(opts.get("params") or params))
    if not truth:
        r.fail("truth", "give the true value of at least one parameter, e.g. t_U1 = \"4 mm\"")
    out = {}
    for k, v in truth.items():
        unit = params[k].unit
        out[k] = r.number(v, f"truth.{k}") if unit == "1" and not isinstance(v, str) else r.q(v, unit, f"truth.{k}")
    return out


def _numbers(r, value, where, lo, hi, example) -> list:
    if not isinstance(value, list) or not value or len(value) > 100:
        r.fail(where, f"give {example}, got {shown(value)}")
    out = [r.number(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if not all(lo <= v <= hi for v in out):
        r.fail(where, f"give {example}, got {shown(value)}")
    return out


def _choices(r, value, where, allowed) -> list:
    if not isinstance(value, list) or not value or len(value) > 20:
        r.fail(where, f"give a list of some of {allowed}, got {shown(value)}")
    bad = [v for v in value if not isinstance(v, str) or v not in allowed]
    if bad:
        r.fail(where, f"{shown(bad[0])} is unknown; choose from {allowed}")
    return list(value)


def _file(r, path: Path, s: dict, key: str) -> Path:
    if key not in s:
        r.fail(f"study.{key}", "missing: case 'board' needs board = \"board.toml\" and points = \"points.csv\"")
    name = r.text(s[key], f"study.{key}", 400)
    if not (path.parent / name).is_file():
        r.fail(f"study.{key}", f"{name!r}: no such file next to {path.name}")
    return path.parent / name
