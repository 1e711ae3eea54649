"""Experimental modal analysis: modal parameters identified from measured FRFs (LSCF poles over
model orders, stabilisation chart, automatic or manual pole choice, LSFD residues, real shapes).

A layer above testdata/ and correlation/ (it reads FRFs and uses the MAC); below the commands."""

from .identify import Identification, identify

__all__ = ["Identification", "identify"]
