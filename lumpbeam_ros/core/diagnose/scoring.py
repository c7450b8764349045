"""Scoring the candidate models and naming a winner only when the data insist on it.

Scores are the Bayesian information criterion with the measurement-error floor estimated
from the data (:mod:`~lumpbeam_ros.core.diagnose.noise`: white noise, or what a free-form fit of
the decay leaves when the sensor's error is smooth), so ``chi2`` is a sum of squared
error-normalized residuals: ``BIC = chi2 / phi + k ln n``. ``phi`` >= 1 inflates the noise
for autocorrelated residuals, ``(1 + rho) / (1 - rho)`` with ``rho`` the lag-1
autocorrelation of the best model's residuals: when even the best model leaves a correlated
pattern, ``n`` samples do not carry ``n`` independent pieces of evidence, and chi2
differences shrink accordingly.

A BIC difference above 10 is "very strong" evidence (Kass and Raftery, 1995). The decision:

1. the best candidate must beat the nominal model and the runner-up each by more than
   ``SIGNIFICANT_BIC``, and also on the held-out end of the record;
2. it must explain the data: its reduced chi2 on the whole record below ``EXPLAINED_CHI2``
   (a right model sits at 1);
3. its parameter must be physical (inside the plausible range, not at a search bound).

Then it is named. Otherwise the answer is ``none`` when the nominal model itself explains the
data (rule 2), and ``unexplained`` when it does not.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

NONE = 'none'
UNEXPLAINED = 'unexplained'

#: BIC margin of a named winner over the nominal model and over the runner-up.
SIGNIFICANT_BIC = 10.0

#: Reduced chi2 up to which a model explains the data "down to the noise". A right model
#: scores 1 +- a few percent (the noise estimate's own error); 1.5 is a 22 % larger RMS.
EXPLAINED_CHI2 = 1.5


@dataclass(frozen=True)
class Score:
    """One model's figures of merit.

    Attributes:
        name: The model (``'nominal'`` or an effect).
        parameters: Its fitted parameters (SI), the refit nominal ones included.
        bic: Information criterion on the training part (lower is better).
        aic: Akaike's criterion on the same chi2, for reference.
        train_chi2: Reduced chi2 on the training part.
        holdout_chi2: Reduced chi2 on the held-out part (fitted parameters kept fixed).
        record_chi2: Reduced chi2 over the whole record.
        physical: Whether the parameters are plausible.
    """

    name: str
    parameters: dict[str, float]
    bic: float
    aic: float
    train_chi2: float
    holdout_chi2: float
    record_chi2: float
    physical: bool


@dataclass(frozen=True)
class Decision:
    """The verdict and why.

    Attributes:
        missing_effect: An effect name, ``'none'`` or ``'unexplained'``.
        best: The best-scoring candidate effect (named or not).
        reason: One sentence for the human summary.
    """

    missing_effect: str
    best: str
    reason: str


def inflation(residuals: np.ndarray, channels: int = 2) -> float:
    """Variance inflation ``(1 + rho) / (1 - rho)`` of residuals, at least 1.

    Args:
        residuals: Noise-normalized residuals, the channels stacked one after the other.
        channels: How many equal-length channels are stacked (the lag never crosses them).

    Returns:
        The inflation factor.
    """
    parts = np.split(np.asarray(residuals, dtype=float), channels)
    num = sum(float(np.dot(p[1:], p[:-1])) for p in parts)
    den = sum(float(np.dot(p, p)) for p in parts)
    rho = min(num / den, 0.999) if den > 0 else 0.0
    return max(1.0, (1.0 + rho) / (1.0 - rho))


def information_criteria(
    chi2: float, n_residuals: int, n_parameters: int, phi: float
) -> tuple[float, float]:
    """``(BIC, AIC)`` from a chi2 with known noise, deflated by ``phi``."""
    evidence = chi2 / phi
    return (
        evidence + n_parameters * math.log(n_residuals / phi),
        evidence + 2.0 * n_parameters,
    )


@dataclass(frozen=True)
class RoundDecision:
    """One round of forward selection: whether the best candidate joins the model.

    Attributes:
        keep: The best candidate is added.
        best: The best-scoring candidate (added or not).
        reason: One sentence for the human summary.
        unphysical: The data insist on the best candidate, but only with an implausible
            parameter: the answer is ``unexplained``.
    """

    keep: bool
    best: str
    reason: str
    unphysical: bool = False


def decide_round(base: Score, candidates: Sequence[Score]) -> RoundDecision:
    """Whether the best candidate improves on the current model (rules 1 and 3).

    The best (lowest BIC) must beat ``base`` and the runner-up each by ``SIGNIFICANT_BIC``,
    and both of them on the held-out part; it must be physical.

    Args:
        base: The current model's score (the nominal model in the first round).
        candidates: The current model plus one more effect, one score each.

    Returns:
        The round's decision.
    """
    ranked = sorted(candidates, key=lambda s: s.bic)
    best = ranked[0]
    runner = ranked[1] if len(ranked) > 1 else base
    margin_base = base.bic - best.bic
    margin_runner = runner.bic - best.bic
    if margin_base < SIGNIFICANT_BIC:
        return RoundDecision(
            False,
            best.name,
            f'no effect improves on {base.name} significantly (best {best.name}, '
            f'dBIC {margin_base:.1f})',
        )
    if margin_runner < SIGNIFICANT_BIC or best.holdout_chi2 >= runner.holdout_chi2:
        return RoundDecision(
            False,
            best.name,
            f'{best.name} and {runner.name} explain the data about equally '
            f'(dBIC {margin_runner:.1f}, held-out chi2 {best.holdout_chi2:.2f} vs '
            f'{runner.holdout_chi2:.2f})',
        )
    if best.holdout_chi2 >= base.holdout_chi2:
        return RoundDecision(
            False, best.name, f'{best.name} does not improve the held-out part of the record'
        )
    if not best.physical:
        return RoundDecision(
            False,
            best.name,
            f'the best candidate, {best.name}, needs an unphysical parameter {best.parameters}',
            unphysical=True,
        )
    return RoundDecision(
        True,
        best.name,
        f'{best.name} beats {base.name} by dBIC {margin_base:.0f} and the runner-up '
        f'{runner.name} by {margin_runner:.0f}; held-out chi2/n {best.holdout_chi2:.2f}',
    )


def explains(score: Score) -> bool:
    """Rule 2: reduced chi2 below ``EXPLAINED_CHI2`` on the whole record and held out."""
    return max(score.record_chi2, score.holdout_chi2) < EXPLAINED_CHI2


def unexplained_reason(score: Score) -> str:
    """Why a model that does not explain the data (rule 2) makes the answer ``unexplained``."""
    return (
        f'the best model, {score.name}, leaves chi2/n {score.record_chi2:.2f} '
        f'(held-out {score.holdout_chi2:.2f}): a gap no library effect explains'
    )


def decide(nominal: Score, candidates: Sequence[Score]) -> Decision:
    """Names one missing effect, or ``none``, or ``unexplained`` (see the module docstring).

    Args:
        nominal: The nominal model's score.
        candidates: One score per effect.

    Returns:
        The decision.
    """
    verdict = decide_round(nominal, candidates)
    best = min(candidates, key=lambda s: s.bic)
    if verdict.keep:
        if not explains(best):
            return Decision(UNEXPLAINED, best.name, unexplained_reason(best))
        return Decision(best.name, best.name, verdict.reason)
    if verdict.unphysical or not explains(nominal):
        return Decision(UNEXPLAINED, best.name, verdict.reason)
    return Decision(NONE, best.name, verdict.reason)
