"""Datasheet values the record cannot decide: a term of the selected structure that
another kind of term fits as well (the core's ``NoiseFit.ambiguous``).

The rise of the longest taus is a rate random walk, a rate ramp or the near side of a
slow Gauss–Markov bump; where the alternative's BIC is less than 2 above the chosen
structure's (below "positive" evidence on Kass and Raftery's scale), the value read
off the chosen one is a guess, and the model reports it as not resolved.
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
    noun, alternative : str
        The term's kind and the alternative's, in words (``"rate random walk"``,
        ``"rate ramp"``, ``"Gauss–Markov bump"``).
    delta_bic : float
        The alternative structure's BIC minus the chosen one's (< 2).
    value : float
        What the chosen structure gave the term (not reported as its value).
    """

    term: str
    noun: str
    alternative: str
    delta_bic: float
    value: float

    def note(self) -> str:
        """The sentence ``model.notes`` carries."""
        return (f"{self.term} is not resolved: a {self.alternative} in place of the "
                f"{self.noun} fits the curve as well (BIC {self.delta_bic:+.2g}, under the 2 "
                "that positive evidence asks), so the record cannot tell them apart; as a "
                f"{self.noun} it would be {self.value:.3g}, and model.upper['{self.term}'] "
                "bounds it")


def ties(raw, fitted) -> tuple[Tie, ...]:
    """One channel's ties from the core's (kind, alternative kind, ΔBIC) triples;
    ``fitted``: {term: the chosen structure's value}."""
    out = []
    for kind, alternative, delta in raw:
        term = _typed.KINDS[kind]
        out.append(Tie(term.name, term.noun, _typed.KINDS[alternative].noun, float(delta),
                       float(fitted[term.name])))
    return tuple(out)
