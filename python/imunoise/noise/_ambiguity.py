"""Datasheet values the record cannot decide: a term of the selected structure that
another kind of term fits as well (the core's ``NoiseFit.ambiguous``).

The rise of the longest taus is a rate random walk, a rate ramp or the near side of a
slow Gauss–Markov bump, and the best structure the selection finds without the term
may describe the curve as well by other means; where such an alternative's BIC is less
than 2 above the chosen structure's (below "positive" evidence on Kass and Raftery's
scale), the value read off the chosen one is a guess, and the model reports it as not
resolved.
"""

from __future__ import annotations

from dataclasses import dataclass

from imunoise.noise import _typed


@dataclass(frozen=True)
class Tie:
    """A datasheet term the data do not tell from an alternative.

    Attributes
    ----------
    term : str
        The datasheet value not resolved (``"K"`` or ``"R"``).
    noun : str
        The term's kind in words (``"rate random walk"``, ``"rate ramp"``).
    alternative : str or None
        The kind that describes its part of the curve instead, in words (``"rate
        ramp"``, ``"Gauss–Markov bump"``); None where the alternative structure
        simply does without the term.
    delta_bic : float
        The alternative structure's BIC minus the chosen one's (< 2).
    value : float
        What the chosen structure gave the term (not reported as its value).
    """

    term: str
    noun: str
    alternative: str | None
    delta_bic: float
    value: float

    def instead(self) -> str:
        """What fits as well: ``"a rate ramp in place of the rate random walk"``."""
        if self.alternative is None:
            return f"a structure without the {self.noun}"
        return f"a {self.alternative} in place of the {self.noun}"

    def note(self) -> str:
        """The sentence ``model.notes`` carries."""
        return (f"{self.term} is not resolved: {self.instead()} fits the curve as well (BIC "
                f"{self.delta_bic:+.2g}, under the 2 that positive evidence asks), so the "
                f"record cannot tell them apart; as a {self.noun} it would be "
                f"{self.value:.3g}, and model.upper['{self.term}'] bounds it")


def ties(raw, fitted) -> tuple[Tie, ...]:
    """One channel's ties from the core's (kind, alternative kind or None, ΔBIC) triples;
    ``fitted``: {term: the chosen structure's value}."""
    out = []
    for kind, alternative, delta in raw:
        term = _typed.KINDS[kind]
        noun = None if alternative is None else _typed.KINDS[alternative].noun
        out.append(Tie(term.name, term.noun, noun, float(delta), float(fitted[term.name])))
    return tuple(out)
