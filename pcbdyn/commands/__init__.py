"""Click commands, one module each (``command`` is the click object); ``pcbdyn.cli`` collects them."""
