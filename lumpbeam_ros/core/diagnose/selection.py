"""Forward selection over the effect library: which effects, one or two at once, are missing.

A :class:`Model` is the nominal beam plus any number of effects, fitted jointly (k_tE, beta
and one strength per effect). The selection grows it one effect per round:

1. Round 1 fits every single effect of the library on the training part of the record,
   each from the better of its own start and the linearized step of 2., or from a start
   informed by the effect's signature.
2. From round 2 on, the current model's residual is linearized: one Gauss-Newton step
   (the current model's Jacobian plus one column per remaining effect, at a small strength)
   predicts how much each effect would lower chi2, and only the most promising are fitted
   in full (``FULL_FITS``, and only those predicted to matter by ``SCREEN_BIC``).
3. A round adds its best candidate only when it beats the current model by
   ``SIGNIFICANT_BIC``, the runner-up too, improves the held-out part, and has a physical
   parameter (:func:`~lumpbeam_ros.core.diagnose.scoring.decide_round`). The selection stops when
   no candidate does (the rest is noise), at ``max_effects``, or at an unphysical winner.

How sure the answer is: each round's choice (stopping included) carries its BIC posterior
probability among the round's options, ``exp(-BIC/2)`` normalized (fitted candidates by
their BIC, screened-out ones by the BIC the linear step predicted); ``confidence`` is the
product over the rounds.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from lumpbeam_ros.core.diagnose.candidates import Candidate, nominal_candidate
from lumpbeam_ros.core.diagnose.fitting import DIFF_STEP, Fit, FitProblem
from lumpbeam_ros.core.diagnose.scoring import (
    SIGNIFICANT_BIC,
    RoundDecision,
    Score,
    decide_round,
    inflation,
    information_criteria,
)
from lumpbeam_ros.core.model.parameters import BeamParameters

#: Largest number of effects named at once.
MAX_EFFECTS = 2

#: Shortest free decay (s) on which a pair is searched: shorter, one effect at most.
PAIR_MIN_DECAY_S = 3.0

#: Candidates fitted in full per round after the first (the best screened).
FULL_FITS = 2

#: Predicted BIC gain below which a screened candidate is not fitted: well under
#: ``SIGNIFICANT_BIC``, since the linear step is only a guide.
SCREEN_BIC = 0.3 * SIGNIFICANT_BIC


@dataclass(frozen=True)
class Model:
    """The nominal beam plus effects, fitted jointly.

    ``x = [ln k/k0, ln beta/beta0, strength_1, ..., strength_m]``, each strength in its
    candidate's units (:class:`~lumpbeam_ros.core.diagnose.candidates.Candidate`).

    Attributes:
        effects: The added effects, in the order chosen.
    """

    effects: tuple[Candidate, ...] = ()

    @property
    def name(self) -> str:
        """``'nominal'`` or the effect names joined by ``+``."""
        return '+'.join(self.names) if self.effects else nominal_candidate().name

    @property
    def names(self) -> tuple[str, ...]:
        """The effect names, in the order chosen."""
        return tuple(c.name for c in self.effects)

    @property
    def n_parameters(self) -> int:
        """k_tE, beta and one strength per effect."""
        return 2 + len(self.effects)

    def plus(self, candidate: Candidate) -> Model:
        """This model with one more effect."""
        return Model((*self.effects, candidate))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of ``x``."""
        lo, hi = nominal_candidate().bounds()
        for c in self.effects:
            c_lo, c_hi = c.bounds()
            lo, hi = np.r_[lo, c_lo[2]], np.r_[hi, c_hi[2]]
        return lo, hi

    def step_floor(self) -> np.ndarray:
        """Each parameter's finite-difference floor (:meth:`Candidate.step_floor`)."""
        floors = [c.step_floor()[2:] for c in self.effects]
        return np.concatenate([nominal_candidate().step_floor(), *floors])

    def beam(self, nominal: BeamParameters, x: np.ndarray) -> BeamParameters:
        """The beam that ``x`` describes: the refit nominal one with every effect on."""
        beam = nominal_candidate().beam(nominal, x)
        effects = beam.effects
        for c, strength in zip(self.effects, x[2:], strict=True):
            value = c.parameter_value(float(strength))
            effects = effects.with_effect(c.name, 0.0 if math.isinf(value) else value)
        return replace(beam, effects=effects)

    def effect_values(self, x: np.ndarray) -> list[tuple[str, dict[str, float]]]:
        """``(name, {parameter: value})`` of each effect at ``x``."""
        return [
            (c.name, {str(c.parameter): c.parameter_value(float(s))})
            for c, s in zip(self.effects, x[2:], strict=True)
        ]

    def values(self, nominal: BeamParameters, x: np.ndarray) -> dict[str, float]:
        """All fitted parameters by name: the refit nominal ones and each effect's."""
        out = nominal_candidate().values(nominal, x)
        for _, params in self.effect_values(x):
            out.update(params)
        return out

    def physical(self, x: np.ndarray) -> bool:
        """Nominal parameters off their bounds, every strength plausible."""
        return nominal_candidate().physical(x[:2]) and all(
            c.strength_physical(float(s)) for c, s in zip(self.effects, x[2:], strict=True)
        )


@dataclass(frozen=True)
class Evaluated:
    """A fit on the training part, simulated over the whole record and scored.

    Attributes:
        fit: The fit.
        residuals: Its residuals over the whole record (z then pitch).
        score: Its figures of merit.
    """

    fit: Fit
    residuals: np.ndarray
    score: Score

    @property
    def model(self) -> Model:
        """The fitted model."""
        model = self.fit.candidate
        assert isinstance(model, Model)
        return model


@dataclass(frozen=True)
class Round:
    """One round of the selection.

    Attributes:
        base: The model the round started from.
        fitted: The candidates fitted in full, scored.
        screened: Predicted BIC of every candidate (round 1: none, all are fitted).
        decision: Whether the best joined the model, and why.
        posterior: BIC posterior probability of the round's choice (adding the best, or
            stopping).
    """

    base: Evaluated
    fitted: list[Evaluated]
    screened: dict[str, float]
    decision: RoundDecision
    posterior: float

    def as_dict(self) -> dict[str, Any]:
        """The JSON form (``details.rounds``)."""
        return {
            'base': self.base.model.name,
            'base_bic': self.base.score.bic,
            'fitted': [
                {
                    'name': e.fit.candidate.name,
                    'bic': e.score.bic,
                    'holdout_chi2': e.score.holdout_chi2,
                    'physical': e.score.physical,
                }
                for e in sorted(self.fitted, key=lambda e: e.score.bic)
            ],
            'screened_bic': dict(self.screened),
            'added': self.decision.best if self.decision.keep else None,
            'reason': self.decision.reason,
            'posterior': self.posterior,
        }


@dataclass(frozen=True)
class Selection:
    """What the forward selection found.

    Attributes:
        model: The selected model's fit on the training part (the nominal one if nothing).
        rounds: Every round, in order.
        singles: Round 1's scores of every single effect.
        nominal: The nominal model, evaluated.
        unphysical: A round's winner needed an implausible parameter.
        confidence: Product of the rounds' posteriors.
        path: The evaluated model after each added effect (nominal first).
    """

    model: Evaluated
    rounds: list[Round]
    singles: list[Score]
    nominal: Evaluated
    unphysical: bool
    confidence: float
    path: list[Evaluated] = field(default_factory=list)


class Selector:
    """Scores fits of a record's training part and runs the rounds.

    Args:
        problem: The record, its noise and the nominal beam.
        train: Mask of the training samples.
        train_end: Last training time, s.
    """

    def __init__(self, problem: FitProblem, train: np.ndarray, train_end: float):
        self.problem = problem
        self.train = train
        self.train_end = train_end
        self.n_train = int(2 * np.count_nonzero(train))
        self.phi = 1.0

    def _both(self, mask: np.ndarray) -> np.ndarray:
        return np.concatenate([mask, mask])

    def evaluate(self, fit: Fit) -> Evaluated:
        """Simulates a training fit over the whole record and scores it (with ``phi``)."""
        residuals = self.problem.model_residuals(fit.candidate, fit.x)
        return Evaluated(fit, residuals, self.score(fit, residuals))

    def score(self, fit: Fit, residuals: np.ndarray) -> Score:
        """A fit's figures of merit (:mod:`~lumpbeam_ros.core.diagnose.scoring`)."""
        bic, aic = information_criteria(
            fit.chi2, self.n_train, fit.candidate.n_parameters, self.phi
        )
        held = ~self.train
        model = fit.candidate
        assert isinstance(model, Model)
        return Score(
            name=fit.name,
            parameters=model.values(self.problem.nominal, fit.x),
            bic=bic,
            aic=aic,
            train_chi2=fit.reduced_chi2,
            holdout_chi2=float(np.mean(residuals[self._both(held)] ** 2)),
            record_chi2=float(np.mean(residuals**2)),
            physical=fit.physical,
        )

    def rescore(self, evaluated: Evaluated) -> Evaluated:
        """The same fit scored with the current ``phi``."""
        return Evaluated(
            evaluated.fit, evaluated.residuals, self.score(evaluated.fit, evaluated.residuals)
        )

    def fit(
        self,
        model: Model,
        x0: np.ndarray,
        alternatives: Sequence[np.ndarray] = (),
        base: Evaluated | None = None,
    ) -> Evaluated:
        """Fits a model on the training part and evaluates it.

        Args:
            model: The model.
            x0: Its starting parameters.
            alternatives: Other starting points (:meth:`FitProblem.fit`).
            base: The fitted model this one extends: its solver remainders start the
                simulations' sweeps.
        """
        warm = None if base is None else base.fit.warm
        return self.evaluate(
            self.problem.fit(model, x0, self.train_end, alternatives=alternatives, warm=warm)
        )

    def predicted_bic(self, chi2: float, n_parameters: int) -> float:
        """The BIC a fit of ``chi2`` would score."""
        return information_criteria(chi2, self.n_train, n_parameters, self.phi)[0]

    def _jacobian(self, model: Model, x: np.ndarray, r0: np.ndarray) -> np.ndarray:
        """Forward-difference Jacobian of a model's training residuals ``r0`` at ``x``."""
        lo, hi = model.bounds()
        columns = []
        for i in range(x.size):
            step = DIFF_STEP * max(1.0, abs(float(x[i])))
            step = step if x[i] + step <= hi[i] else -step
            shifted = x.copy()
            shifted[i] += step
            columns.append(
                (self.problem.model_residuals(model, shifted, self.train_end) - r0) / step
            )
        return np.column_stack(columns)

    def screen(
        self, base: Evaluated, candidates: Sequence[Candidate]
    ) -> dict[str, tuple[float, float, np.ndarray]]:
        """One linearized Gauss-Newton step per candidate added to ``base``.

        The base model's Jacobian on the training part (forward differences) and one column
        per candidate (its residual change at its starting strength) give the least-squares
        step of the base parameters and the new strength; an effect without a sign whose
        step is negative predicts no gain.

        Args:
            base: The current model, fitted.
            candidates: The effects that may join it.

        Returns:
            ``{name: (predicted chi2, predicted strength, predicted x)}``: ``x`` is the
            wider model's parameters after the step.
        """
        model, x = base.model, base.fit.x
        end = self.train_end
        r0 = self.problem.model_residuals(model, x, end)
        # Its own steps, not the fit's last Jacobian: those are relative to the parameters,
        # and a strength near 0 would see no slope (the predictions set the fits' starts).
        jacobian = self._jacobian(model, x, r0)
        out = {}
        for c in candidates:
            wider = model.plus(c)
            start = c.start / c.scale
            warm = None if base.fit.warm is None else base.fit.warm.copy()
            residuals = self.problem.model_residuals(wider, np.r_[x, start], end, warm)
            column = (residuals - r0) / start
            full = np.column_stack([jacobian, column])
            step, *_ = np.linalg.lstsq(full, -r0, rcond=None)
            strength = float(step[-1])
            if strength <= 0.0 and not c.signed:
                step, *_ = np.linalg.lstsq(jacobian, -r0, rcond=None)
                predicted = float(np.sum((r0 + jacobian @ step) ** 2))
                strength = 0.0
                step = np.r_[step, 0.0]
            else:
                predicted = float(np.sum((r0 + full @ step) ** 2))
            stepped = np.r_[x + step[:-1], strength]
            out[c.name] = (min(predicted, base.fit.chi2), strength, stepped)
        return out


def posterior(chosen: float, options: Sequence[float]) -> float:
    """``exp(-chosen/2)`` normalized over ``exp(-b/2)`` of every option's BIC ``b``."""
    return 1.0 / sum(math.exp(-0.5 * float(np.clip(b - chosen, -1400.0, 1400.0))) for b in options)


def select(
    selector: Selector,
    nominal: Fit,
    candidates: Sequence[Candidate],
    max_effects: int = MAX_EFFECTS,
    start_strength: Callable[[Candidate], float | None] = lambda c: None,
    exhaustive: bool = False,
    informed_start: Callable[[Evaluated, Candidate], np.ndarray | None] = lambda b, c: None,
) -> Selection:
    """Forward selection of effects (see the module docstring).

    Args:
        selector: The record's training part and its scoring.
        nominal: The nominal model fitted on the training part.
        candidates: The library's effects.
        max_effects: Most effects named.
        start_strength: A starting strength for a candidate's round-1 fit (``None``: its
            default), e.g. the time shift seen at the load event for the latency.
        exhaustive: The baseline ``lumpbeam bench`` measures against: every combination of
            up to ``max_effects`` effects fitted from scratch (from the nominal fit), and
            each round choosing among those fits instead of screening.
        informed_start: Where a fit of a candidate added to a fitted model starts instead
            of the generic starts (``None``: those), e.g. dry friction's from the decay
            envelopes. The generic starts are compared by chi2; a start informed by the
            effect's own signature is taken as it is, since one inside the right valley may
            still score worse than one beside it.

    Returns:
        The selection.
    """
    base, fitted = _first_round(selector, nominal, candidates, start_strength, informed_start)
    combinations = (
        _every_combination(selector, nominal, candidates, max_effects) if exhaustive else None
    )
    nominal_evaluated = base
    singles_scores = [e.score for e in fitted]
    rounds: list[Round] = []
    path = [base]
    unphysical = False
    screened: dict[str, float] = {}
    while True:
        decision = decide_round(base.score, [e.score for e in fitted])
        options = [base.score.bic, *(e.score.bic for e in fitted), *screened.values()]
        best = min(fitted, key=lambda e: e.score.bic)
        chosen = best.score.bic if decision.keep else base.score.bic
        rounds.append(Round(base, fitted, screened, decision, posterior(chosen, options)))
        if not decision.keep:
            unphysical = decision.unphysical
            break
        base = best
        path.append(base)
        if len(base.model.effects) >= max_effects:
            break
        remaining = [c for c in candidates if c.name not in base.model.names]
        if combinations is not None:
            names = set(base.model.names)
            fitted = [
                selector.rescore(combinations[frozenset(names | {c.name})]) for c in remaining
            ]
            screened = {}
            continue
        fitted, screened, stop = _screened_round(selector, base, remaining, informed_start)
        if stop is not None:
            rounds.append(stop)
            break
    confidence = math.prod(r.posterior for r in rounds)
    return Selection(
        base, rounds, singles_scores, nominal_evaluated, unphysical, confidence, path=path
    )


def _first_round(
    selector: Selector,
    nominal: Fit,
    candidates: Sequence[Candidate],
    start_strength: Callable[[Candidate], float | None],
    informed_start: Callable[[Evaluated, Candidate], np.ndarray | None],
) -> tuple[Evaluated, list[Evaluated]]:
    """Round 1: the nominal model and every single effect, fitted and scored.

    The residuals' inflation ``phi`` (correlated noise) is estimated on the best training
    fit of them, and every score is given with it.

    Returns:
        The nominal model and the single effects, evaluated with that ``phi``.
    """
    base_fit = Fit(
        Model(),
        nominal.x,
        nominal.beam,
        nominal.chi2,
        nominal.n_residuals,
        nominal.evaluations,
        nominal.physical,
        warm=nominal.warm,
    )
    base = selector.evaluate(base_fit)
    # The linearized step of each effect (as in later rounds) is a second starting point:
    # a fit that starts where the data put it saves most of its iterations, and one the
    # linearization misjudges starts from the candidate's own start as before, whichever
    # fits better. A step that predicts no gain starts the effect off, on its bound: the
    # fit leaves it when the data's slope says so, its finite differences being taken at
    # least at the starting strength's scale (:meth:`Candidate.step_floor`).
    predictions = selector.screen(base, candidates)
    singles = []
    for c in candidates:
        informed = informed_start(base, c)
        if informed is not None:
            singles.append(selector.fit(Model((c,)), _plausible_x(c, informed), base=base))
            continue
        singles.append(
            selector.fit(
                Model((c,)),
                c.start_x(nominal.x, start_strength(c)),
                [_plausible_x(c, predictions[c.name][2])],
                base,
            )
        )
    best_train = min([base, *singles], key=lambda e: e.fit.chi2)
    selector.phi = inflation(best_train.residuals[selector._both(selector.train)])
    return selector.rescore(base), [selector.rescore(e) for e in singles]


def _plausible(candidate: Candidate, strength: float) -> float:
    """A linear step's strength kept inside the plausible range.

    A far step is a poor start, and an extreme one may not even simulate.
    """
    limit = candidate.plausible_max / candidate.scale
    return float(np.clip(strength, -limit, limit))


def _plausible_x(candidate: Candidate, x: np.ndarray) -> np.ndarray:
    """A linear step's parameters with the strength kept plausible (:func:`_plausible`)."""
    return np.asarray(np.r_[x[:-1], _plausible(candidate, float(x[-1]))])


def _every_combination(
    selector: Selector, nominal: Fit, candidates: Sequence[Candidate], max_effects: int
) -> dict[frozenset[str], Evaluated]:
    """The exhaustive baseline: every group of 2 to ``max_effects`` effects, fitted.

    Each starts from the nominal fit; its score holds the ``phi`` of the moment, so a round
    rescores it.
    """
    combinations: dict[frozenset[str], Evaluated] = {}
    for size in range(2, max_effects + 1):
        for group in itertools.combinations(candidates, size):
            x0 = np.r_[nominal.x, [c.start / c.scale for c in group]]
            combinations[frozenset(c.name for c in group)] = selector.fit(Model(group), x0)
    return combinations


def _screened_round(
    selector: Selector,
    base: Evaluated,
    remaining: Sequence[Candidate],
    informed_start: Callable[[Evaluated, Candidate], np.ndarray | None] = lambda b, c: None,
) -> tuple[list[Evaluated], dict[str, float], Round | None]:
    """A round after the first: screen every remaining effect, fit the promising ones.

    Returns:
        The candidates fitted in full, the predicted BIC of the others, and the closing
        round when none is predicted to matter (``None`` otherwise).
    """
    predictions = selector.screen(base, remaining)
    k = base.model.n_parameters + 1
    ranked = sorted(predictions, key=lambda name: predictions[name][0])
    promising = [
        name
        for name in ranked[:FULL_FITS]
        if base.score.bic - selector.predicted_bic(predictions[name][0], k) >= SCREEN_BIC
    ]
    screened = {
        name: selector.predicted_bic(predictions[name][0], k)
        for name in ranked
        if name not in promising
    }
    fitted = []
    for name in promising:
        c = next(c for c in remaining if c.name == name)
        informed = informed_start(base, c)
        if informed is None:
            strength = _plausible(c, predictions[name][1]) or c.start / c.scale
            x0 = np.r_[base.fit.x, strength]
        else:
            x0 = _plausible_x(c, informed)
        fitted.append(selector.fit(base.model.plus(c), x0, base=base))
    if fitted:
        return fitted, screened, None
    stop = RoundDecision(
        False, ranked[0] if ranked else '', 'no further effect is predicted to matter'
    )
    chance = posterior(base.score.bic, [base.score.bic, *screened.values()])
    return fitted, screened, Round(base, [], screened, stop, chance)
