"""Design verdicts under vibration: input spectra, base-excited modal response, Steinberg's
fatigue check of parts (solder joints and lead wires), sine sweeps and the octave rule."""

from .assess import Assessment, PartResult, assess
from .damping import Damping, parse_damping
from .parts import judged_parts
from .spectra import G, Psd, SineSweep, VibrationError, analysis_band, load_psd, named_psd, read_sine_csv

__all__ = ["Assessment", "Damping", "G", "PartResult", "Psd", "SineSweep", "VibrationError", "analysis_band",
           "assess", "judged_parts", "load_psd", "named_psd", "parse_damping", "read_sine_csv"]
