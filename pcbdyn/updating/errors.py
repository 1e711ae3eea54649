"""The error of updating runs that the data cause (no measured mode pairs, nothing left to update, no
FRF line to use): a clear message for the user, as opposed to a call with arrays of the wrong shape,
which is a bug of the caller."""


class UpdatingError(ValueError):
    """Measured data and model that give the updating equations nothing to work on; the message says
    what to check or give."""
