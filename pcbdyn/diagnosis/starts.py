"""Where the effect search starts (:func:`.pipeline.diagnose`, step 4), and when it need not start again.

The search is linearised at its start, so a start can hide what the model lacks: it runs from each fit
of the declared parameters the parameter stage offers (:func:`.parameter_stage.parameter_stage`), with
the effects that the test modes without a partner show held (:mod:`.unpaired`; their masses first walked
to where the fitted parameters put them), again without those effects (placed from the starting values'
modes, they may mislead), and from the declared values where the fit alone gave up the frequencies
(:func:`.parameter_stage.declared_origin`). The least criterion wins. Once a start's effects leave a chi^2
within the noise (the chi-square test of thesis section 5.2.3, :meth:`.selection.Selection.within_noise`)
the other starts are not run: they could only offer another explanation the data cannot tell from it,
and each costs a search (a card with a 33 g mass shown by a mode without a partner, dev seed 4: three
searches, two thirds of its 176 s).
"""

from __future__ import annotations

from dataclasses import dataclass

from .fitting import estimate
from .moves import on_node
from .select import refine
from .selection import Selection, adopt, penalty


@dataclass
class Starts:
    """The search's starts on residual ``res`` over candidates ``cands``, with the candidate indices
    ``held`` of the effects ``support`` [(candidate, value)] the unpaired modes show; ``moves``,
    ``bounds``, ``alpha``, ``runner``: as the search takes them; ``say``: progress."""

    res: object
    cands: list
    held: list
    support: list
    moves: object
    bounds: object
    alpha: float
    runner: object
    say: object

    def best(self, search, origins, declared) -> tuple:
        """(the selection of least criterion, whether it ran without the support, whether a search ran from
        the declared values) over the starts, from the fits ``origins`` of the declared parameters (the
        first: the one the noise test weighed, whose chi^2 a search from the declared values must beat);
        ``search(fit, **kw)`` runs one search, ``declared()`` gives the declared values' start or None."""
        found = []
        for run in self._runs(search, origins, declared):
            found.append(run)
            if run[0].within_noise(self.res.n_rows - len(origins[0].p), self.alpha):
                self.say("  what the effects found leave is within the noise: the search's other starts are not run")
                break
        sel, free, _ = min(found, key=lambda r: r[0].criterion[-1])
        return sel, free, any(r[2] for r in found)

    def _runs(self, search, origins, declared):
        """(selection, whether it ran without the support, whether from the declared values) of each start,
        one at a time."""
        res, held = self.res, self.held
        for origin in origins:
            begin, placed = origin, held
            if held:
                self.say("fitting the support with the declared parameters")
                begin = estimate(res, origin.p, [self.cands[i] for i in held], [v for _, v in self.support], 10,
                                 self.bounds)
                begin, placed = self._walked(begin)
            yield search(begin, held=placed), False, False
        if held:
            self.say("searching again without the effects the modes without a partner showed")
            yield search(estimate(res, origins[0].p, [], [], 10, self.bounds)), True, False
            return
        at = declared()
        if at is not None:
            yield search(at, without=origins[0].chi2), False, True

    def _walked(self, fit) -> tuple:
        """(fit, candidate indices) of the held effects (fitted with the declared parameters in ``fit``) after
        their masses walk to where they fit best (:func:`.select.refine`) before the search: placed with
        the model's elastic modes at the parameters' starting values, a mass sits where that model puts
        it, and the search is to find what else is missing, not to make up for a misplaced one. (A spring
        on a free board is placed between nodes from its mode's rigid-body part, which the parameters do
        not change; it stays.)"""
        res, cands, held = self.res, self.cands, self.held
        if not any(on_node(cands[i]) for i in held):
            return fit, held
        self.say("walking the masses to where the fitted parameters put them")
        sel = refine(res, cands, adopt(Selection(), held, fit, penalty(res.n_rows, len(cands), self.alpha)),
                     lambda i: self.moves(i) if on_node(cands[i]) else [], self.bounds, alpha=self.alpha,
                     runner=self.runner)
        if sel.chosen == list(held):
            return fit, held
        return estimate(res, sel.p, [cands[i] for i in sel.chosen], sel.values, 10, self.bounds), list(sel.chosen)
