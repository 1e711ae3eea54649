"""Measured data: points, modes and FRFs; UFF and CSV in and out; noise and simulated tests."""

from .data import FRFs, Dofs, Excitation, MeasuredModes, Points, TestData, TestDataError, excitations
from .uff import read_uff, real_modes, write_uff
from .csvio import read_modes_csv, read_points_csv, write_modes_csv, write_points_csv
from .noise import Noise, add_noise, noisy_frequencies, noisy_frfs, noisy_shapes

__all__ = [
    "FRFs", "Dofs", "Excitation", "MeasuredModes", "excitations", "Points", "TestData", "TestDataError", "read_uff", "write_uff", "real_modes",
    "read_modes_csv", "read_points_csv", "write_modes_csv", "write_points_csv",
    "Noise", "add_noise", "noisy_frequencies", "noisy_frfs", "noisy_shapes",
]
