"""Element kernels. Each maps node coordinates ``xyz`` (n_cells, nodes_per_cell, 3) and one property
to stiffness and mass matrices (n_cells, 6 * nodes_per_cell, 6 * nodes_per_cell) in global axes,
vectorised over cells.
"""

from . import beam, discrete, edge_joint, edge_spring, embedded_beam, shell_quad4, shell_tri3

#: element type -> its matrices function
KERNELS = {
    "spring": discrete.spring_matrices,
    "mass": discrete.mass_matrices,
    "quad4": shell_quad4.matrices,
    "tri3": shell_tri3.matrices,
    "beam2": beam.matrices,
    "embedded_beam2": embedded_beam.matrices,
    "edge_spring": edge_spring.matrices,
    "edge_joint": edge_joint.matrices,
}


def kernel(etype: str):
    """The matrices function for an element type."""
    try:
        return KERNELS[etype]
    except KeyError:
        raise KeyError(f"no element kernel registered for '{etype}'") from None
