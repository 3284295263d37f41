"""imunoise.plan: its promise holds in simulated records of the planned length."""

from __future__ import annotations

import imunoise
import numpy as np
import pytest
from imunoise.noise._terms import model_variance
from imunoise.planner import plan

SIMULATIONS = 40


def _met(p, term: str, fs: float) -> float:
    """Share of simulated records of the planned length whose ADEV at the term's tau
    is within the target of the true one."""
    c, t = p.coefficients, p.terms[term]
    n = int(np.ceil(t.seconds * fs))
    hits = 0
    for seed in range(SIMULATIONS):
        y = imunoise.simulate(n, fs, N=c["N"], B=c["B"], K=c["K"], seed=seed)
        r = imunoise.adev(y, fs, taus=np.array([t.tau]))
        true = np.sqrt(model_variance(r.taus, N=c["N"], B=c["B"], K=c["K"]))[0]
        hits += abs(r.dev[0] / true - 1) <= p.target
    return hits / SIMULATIONS


@pytest.mark.parametrize("term, fs", [("N", 40.0), ("B", 1.0), ("K", 1.0)])
def test_plan_vn100_promise_is_met_in_90_percent_of_simulated_records(term, fs):
    p = plan("vn100", fs=fs, target=0.2)
    assert _met(p, term, fs) >= 0.9


def test_a_shorter_record_does_not_keep_the_promise():
    """The check above can fail: a quarter of the planned length misses it."""
    p = plan("vn100", fs=1.0, target=0.2)
    short = type(p)(fs=p.fs, target=p.target, confidence=p.confidence,
                    terms={"B": type(p.terms["B"])("B", p.terms["B"].value, p.terms["B"].tau,
                                                   p.terms["B"].seconds / 4)},
                    coefficients=p.coefficients)
    assert _met(short, "B", 1.0) < 0.9
    assert p.uncertainty(p.terms["B"].seconds / 4)["B"] > 0.2 >= p.uncertainty(
        p.terms["B"].seconds)["B"]


def test_plan_numbers_and_errors():
    p = plan("vn100", fs=40.0)
    assert p.terms["N"].tau == 1.0 and p.terms["N"].seconds < p.terms["B"].seconds \
        < p.terms["K"].seconds == p.seconds
    assert "needs N" in p.line() and "resolves" in p.line(3600)
    assert plan({"N": 1e-4, "B": 0.0, "K": 0.0}).terms.keys() == {"N"}
    assert "no N, B or K" in plan({}).line(60)
    with pytest.raises(ValueError, match="target"):
        plan("vn100", target=0)
    with pytest.raises(ValueError, match="coefficients must be finite"):
        plan({"N": -1.0})


def test_b_without_a_walk_is_read_where_its_floor_dominates():
    # No K: the curve only flattens, so B's tau is where the floor is 3x the rest,
    # not the end of the search grid (1e9 s, "> 1000 h" before).
    plan = imunoise.plan({"N": 1e-4, "B": 3.8e-5, "K": 0.0}, fs=40.0)
    tau = plan.terms["B"].tau
    assert 1.0 < tau < 1e4
    assert 0.6643**2 * 3.8e-5**2 >= 2.9 * 1e-8 / tau
    assert plan.terms["B"].seconds < 3.6e6


def test_a_datasheet_without_k_says_k_is_assumed():
    from imunoise.planner import plan

    line = plan("vn100").line()
    assert "K " in line and "K: not on the datasheet, a typical value is assumed" in line
    assert plan({"N": 1e-4, "B": 1e-5, "K": 1e-6}).assumed == ()
