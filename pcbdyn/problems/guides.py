"""A board's wedge-lock guides as the two-step strategy of thesis section 7.4 needs them: the board with
every guide hinged or clamped (the two extremes, Tables 7.8-7.9 and 7.12-7.13), and the board with the
guides as rotational springs whose stiffness is one parameter shared by all guides or one per guide
(updated on a log scale, Tables 7.10-7.11 and 7.14-7.15). The variants are made from the loaded Board
(``dataclasses.replace``), never by editing its text."""

from __future__ import annotations

from dataclasses import replace

from .. import targets
from ..board.entries import BoardError
from ..targets import KINDS, ParameterSpec

#: the quantity a guide's stiffness is (display unit and log scale from the one table of targets)
K_ROT = KINDS["fixtures", "k_rot"]
#: the stiffness range searched, in units of the board's bending stiffness over its span across the
#: guides (D / L): k L / D = 0.01 is a hinge to within a fraction of a percent, 1e4 a clamp
RANGE = (1e-2, 1e4)


def wedge_locks(board) -> list:
    """The board's wedge_lock fixtures; a BoardError when it has none (nothing to fit)."""
    guides = [f for f in getattr(board, "fixtures", []) if f.type == "wedge_lock"]
    if not guides:
        raise BoardError(f"{board.path.name}: no [[fixtures]] of type \"wedge_lock\": the two-step guide fit needs the "
                         "card's guides, e.g. [[fixtures]] name = \"bottom_guide\", type = \"wedge_lock\", "
                         "edge = \"y=0\", k_rot = \"1e4 N*m/rad/m\"")
    return guides


def target(fixture_name: str) -> str:
    """The target of the rotational stiffness of guide ``fixture_name``."""
    return targets.target("fixtures", fixture_name, "k_rot")


def with_guides(board, k: dict, parameters: list = ()):
    """The board with each guide of ``k`` {fixture name: "hinged", "clamped" or N*m/rad/m} set so, its
    [[parameters]] that address a guide's stiffness replaced by ``parameters`` (ParameterSpec)."""
    names = {f.name for f in wedge_locks(board)}
    fixtures = [replace(f, k_rot=k[f.name]) if f.name in k else f for f in board.fixtures]
    own = {target(n) for n in names}
    kept = [p for p in board.parameters if not own & set(p.targets)]
    return replace(board, fixtures=fixtures, parameters=kept + list(parameters))


def extreme(board, kind: str):
    """The board with every guide ``kind`` ("hinged": the springs removed; "clamped": the rotation
    about the edge held), as the thesis computes the two limits (section 7.4.2)."""
    return with_guides(board, {f.name: kind for f in wedge_locks(board)})


def spring_groups(board, per_guide: bool) -> dict:
    """{parameter name: [fixture names]}: one stiffness ``k_rot`` shared by all guides, or ``k_<name>``
    per guide."""
    names = [f.name for f in wedge_locks(board)]
    return {f"k_{n}": [n] for n in names} if per_guide else {"k_rot": names}


def stiffness_range(board) -> tuple:
    """(lower, upper) [N*m/rad/m] of a guide's stiffness between hinged and clamped: :data:`RANGE` times
    D / L, D the bare board's bending stiffness across the guides and L its span across them (the
    largest over the guides)."""
    lo, hi = board.outline.bbox
    scale = 0.0
    for f in wedge_locks(board):
        axis = f.edge[0]
        D = float(board.plate.bending()[axis, axis])
        scale = max(scale, D / float(hi[axis] - lo[axis]))
    return RANGE[0] * scale, RANGE[1] * scale


def springs(board, groups: dict, k0: dict, bounds: tuple):
    """The board with its guides as rotational springs: parameter ``name`` of ``groups`` sets the
    stiffness of its fixtures, starting at ``k0[name]`` [N*m/rad/m], within ``bounds``, on a log scale."""
    specs = [ParameterSpec(name, [target(n) for n in fixtures], tuple(bounds), K_ROT.unit, K_ROT.log, float(k0[name]))
             for name, fixtures in groups.items()]
    return with_guides(board, {n: float(k0[name]) for name, fixtures in groups.items() for n in fixtures}, specs)
