"""The HTML pages of ``pcbdyn build`` and ``pcbdyn correlate`` (see :mod:`.html` for the builder):
the same tables and pictures the commands write, on one self-contained page."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .html import Page, describe_file


def build_page(out: Path, board_toml, board, solved: list) -> Path:
    """report.html in ``out`` from :func:`pcbdyn.commands.build.analyse` results (one per configuration):
    the model, the modes table, an animated 3-D view of the modes and the mode pictures in ``out/png``."""
    from .modes import MASS_NOTE, free_note
    from .view3d import MAX_BYTES, shapes_view

    results = [r["summary"] for r in solved]
    page = Page(f"pcbdyn build: {board.name}",
                subtitle=", ".join(f"[{r['configuration']}] first mode {r['modes'][0]['frequency_hz']:.1f} Hz"
                                   for r in results if r["modes"]))
    page.items("Inputs", {"board": describe_file(board_toml),
                          "configurations": ", ".join(r["configuration"] for r in results),
                          "mesh size": f"{board.mesh_size * 1e3:g} mm"})
    for r, s in zip(results, solved):
        label, modes = r["configuration"], s["modes"]
        page.items(f"Model [{label}]", {"mass": f"{r['mass_kg'] * 1e3:.2f} g", "DOFs": r["dofs"],
                                        "rigid-body modes": r["rigid_body_modes"],
                                        "centre of mass [mm]": ", ".join(f"{1e3 * c:.1f}" for c in r["centre_of_mass_m"])})
        page.table(f"Modes [{label}]", s["table"], note=free_note(modes.n_rigid) or MASS_NOTE)
        if modes.frequencies.size:
            page.view3d(f"Modes in 3-D [{label}]", shapes_view(
                f"{board.name} [{label}]", s["model"].model, board.outlines(s["config"]), modes.shapes,
                [f"mode {m['n']}: {m['frequency_hz']:.1f} Hz, {m['shape']}" for m in r["modes"]],
                MAX_BYTES // len(solved)))
        shown = [(out / "png" / f"modes_{label}_{m['n']:02d}.png", m) for m in r["modes"]]
        shown = [(png, m) for png, m in shown if png.is_file()]  # none with --no-pictures
        if shown:
            page.pictures(f"Mode shapes [{label}]", [png for png, _ in shown],
                          [f"mode {m['n']}: {m['frequency_hz']:.1f} Hz, {m['shape']}" for _, m in shown],
                          optional=True)
    return page.write(out / "report.html")


def correlate_page(out: Path, board_toml, test_uff, board, config, corr, written: list, bm, modes,
                   test_modes) -> Path:
    """report.html in ``out`` from a correlation ``corr`` of ``test_modes`` with the model ``bm`` of the
    configuration ``config`` (None: the base) and its ``modes``: the tables, test and model side by side
    in 3-D through the pairs, and the pictures :func:`write_outputs` made."""
    from .view3d import pair_view

    pairing, label = corr.pairing, config or "base"
    comac = dict(zip(corr.dof_labels, corr.comac.tolist()))
    page = Page(f"pcbdyn correlate: {board.name} [{label}] against {Path(test_uff).name}",
                subtitle=f"{len(pairing.pairs)} pair(s); unpaired test modes: "
                         f"{', '.join(str(i + 1) for i in pairing.unpaired_test) or 'none'}")
    page.items("Inputs", {"board": describe_file(board_toml), "test": describe_file(test_uff), "configuration": label})
    pairs = pd.DataFrame([{"test mode": p.test + 1, "model mode": p.model + 1, "f_test [Hz]": p.f_test,
                           "f_model [Hz]": p.f_model, "df [%]": p.df_pct, "MAC": p.mac_combined,
                           "combined with": " ".join(str(c + 1) for c in p.cluster if c != p.model) or "-"}
                          for p in pairing.pairs])
    page.table("Mode pairs", pairs, note="df = (f_model - f_test) / f_test; pairs by MAC (thesis eq. 2.3)")
    lowest = sorted(comac.items(), key=lambda kv: kv[1])[:10]
    page.table("Lowest COMAC", pd.DataFrame([{"DOF": k, "COMAC": v} for k, v in lowest]),
               note="COMAC per measured DOF over the pairs (thesis eq. 2.4); low values mark where test and model "
                    "differ")
    if pairing.pairs:
        page.view3d("Test and model in 3-D", pair_view(
            bm.model, pairing.model_shapes(modes.shapes), board.outlines(config),
            test_modes, pairing.model_shapes(corr.model_at_test), pairing.pairs),
            note="left: the model's shape with the test points on it; right: the measured shape at the test "
                 "points (scaled by its modal scale factor against the model, so both move in phase) over the "
                 "model at rest")
    captions = {"mac_matrix.png": "MAC matrix (pairs framed)", "automac.png": "AutoMAC of the model at the test points",
                "frequencies.png": "model against test frequency", "comac.png": "COMAC per point"}
    main = [n for n in captions if n in written]
    page.pictures("MAC matrix, frequencies and COMAC", [out / n for n in main], [captions[n] for n in main])
    overlays = [n for n in written if n.endswith(".png") and n not in main]
    if overlays:
        page.pictures("Mode shapes, test over model", [out / n for n in overlays], [Path(n).stem for n in overlays])
    return page.write(out / "report.html")
