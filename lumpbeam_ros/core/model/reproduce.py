"""The paper's numbers recomputed with this model: Tables B.1 and B.2, frequencies, statics.

The bookkeeping follows doc/interfaces.md: table rows carry the load at the free end of the last
segment (the ``n_s = 1`` row at that segment's centre), and the paper's frequencies lump the
tip masses into the last segment's centre of mass ("added to m_ns").
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, replace
from importlib import resources

from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters, TipPlacement
from lumpbeam_ros.core.model.statics import static_tip_deflection

#: The tables' end load, kg (section B.3.1).
TABLE_LOAD_KG = 4.5
#: The static test of section B.4, kg.
STATIC_TEST_KG = 6.5
#: Mounted tip mass of the dynamic runs and of the validation run, kg.
MOUNTED_KG = 2.5
VALIDATION_MOUNTED_KG = 4.5


@dataclass(frozen=True)
class TableRow:
    """One row of Table B.1 or B.2: tip deflections, m, for one n_s."""

    n_s: int
    uniform_m: float
    loaded_m: float
    end_load_m: float


@dataclass(frozen=True)
class PaperNumbers:
    """The values reported in reference/paper.txt (shipped as data/paper_numbers.csv)."""

    table_b1: list[TableRow]
    table_b2: list[TableRow]
    scalars: dict[str, float]


def paper_numbers() -> PaperNumbers:
    """Reads the paper's numbers shipped with the package."""
    text = resources.files('lumpbeam_ros.base').joinpath('data/paper_numbers.csv').read_text()
    tables: dict[str, list[TableRow]] = {'B1': [], 'B2': []}
    scalars: dict[str, float] = {}
    for row in csv.reader(line for line in text.splitlines() if not line.startswith('#')):
        if row[0] in tables:
            tables[row[0]].append(TableRow(int(row[1]), *map(float, row[2:5])))
        elif row[0] == 'scalar':
            scalars[row[1]] = float(row[2])
    return PaperNumbers(tables['B1'], tables['B2'], scalars)


def deflection_table(beam: BeamParameters, max_segments: int = 10) -> list[TableRow]:
    """Tables B.1/B.2: tip deflection under the beam's weight, with 4.5 kg, and the difference.

    Args:
        beam: The beam; its stiffness_source picks B.1 (analytic) or B.2 (identified). The
            mounted tip mass is left off, as in the paper's static tables.
        max_segments: Rows for n_s = 1..max_segments.

    Returns:
        The rows.
    """
    rows = []
    bare = replace(beam, tip_mass_kg=0.0, tip_inertia_kgm2=0.0)
    for n in range(1, max_segments + 1):
        placement: TipPlacement = 'segment_com' if n == 1 else 'free_end'
        b = replace(bare, n_segments=n, tip_placement=placement)
        uniform = static_tip_deflection(b)
        loaded = static_tip_deflection(b, TABLE_LOAD_KG)
        rows.append(TableRow(n, uniform, loaded, loaded - uniform))
    return rows


def drop_frequency_hz(beam: BeamParameters, mounted_kg: float) -> float:
    """Damped frequency of the first mode after the drop (load gone, ``m_d`` mounted)."""
    chain = LumpedChain.from_beam(replace(beam, tip_mass_kg=mounted_kg))
    return float(chain_modes(chain).damped_frequency_hz[0])


def paper_frequencies(beam: BeamParameters) -> dict[str, float]:
    """The three frequencies of sections B.3.1, B.3.3 and B.4, in the paper's convention.

    Args:
        beam: The beam (n_s = 10 in the paper).

    Returns:
        ``analytic`` (3.42 Hz), ``identified`` (3.24 Hz) and ``validation`` (2.51 Hz).
    """
    paper = replace(beam, tip_placement='segment_com')
    return {
        'analytic': drop_frequency_hz(replace(paper, stiffness_source='analytic'), MOUNTED_KG),
        'identified': drop_frequency_hz(replace(paper, stiffness_source='identified'), MOUNTED_KG),
        'validation': drop_frequency_hz(
            replace(paper, stiffness_source='identified'), VALIDATION_MOUNTED_KG
        ),
    }


def static_test(beam: BeamParameters) -> dict[str, float]:
    """The 6.5 kg static deflection of section B.4: the model's and Euler-Bernoulli's (B.3)."""
    bare = replace(beam, stiffness_source='identified', tip_mass_kg=0.0, tip_inertia_kgm2=0.0)
    model = static_tip_deflection(bare, STATIC_TEST_KG) - static_tip_deflection(bare)
    force = STATIC_TEST_KG * beam.gravity_mps2
    analytic = rules.end_load_deflection(force, beam.length_m, beam.bending_stiffness_nm2)
    return {'model': model, 'analytic': analytic}


@dataclass(frozen=True)
class Reproduction:
    """This model's values for everything the paper reports (doc/interfaces.md keys)."""

    table_b1: list[TableRow]
    table_b2: list[TableRow]
    frequencies_hz: dict[str, float]
    frequencies_free_end_hz: dict[str, float]
    static_6p5kg_m: dict[str, float]


def reproduce(beam: BeamParameters | None = None) -> Reproduction:
    """Recomputes the paper's tables, frequencies and static deflections.

    Args:
        beam: The beam (default: doc/interfaces.md, 'Beam model', n_s = 10).

    Returns:
        The values, with the frequencies also for tip masses at the free end.
    """
    beam = BeamParameters() if beam is None else beam
    free_end = replace(beam, tip_placement='free_end')
    return Reproduction(
        table_b1=deflection_table(replace(beam, stiffness_source='analytic')),
        table_b2=deflection_table(replace(beam, stiffness_source='identified')),
        frequencies_hz=paper_frequencies(beam),
        frequencies_free_end_hz={
            'analytic': drop_frequency_hz(
                replace(free_end, stiffness_source='analytic'), MOUNTED_KG
            ),
            'identified': drop_frequency_hz(
                replace(free_end, stiffness_source='identified'), MOUNTED_KG
            ),
            'validation': drop_frequency_hz(
                replace(free_end, stiffness_source='identified'), VALIDATION_MOUNTED_KG
            ),
        },
        static_6p5kg_m=static_test(beam),
    )


@dataclass(frozen=True)
class Comparison:
    """One reproduced number beside the paper's, with the tolerance it must meet.

    Attributes:
        what: Which number, e.g. ``'B.1 n_s=3 loaded'``.
        value: This model's value.
        paper: The paper's value.
        tolerance: The largest accepted difference.
        relative: Whether ``tolerance`` is relative (else absolute, in the value's unit).
    """

    what: str
    value: float
    paper: float
    tolerance: float
    relative: bool

    @property
    def difference(self) -> float:
        """Value minus paper, relative to the paper when the tolerance is relative."""
        diff = self.value - self.paper
        return diff / self.paper if self.relative else diff

    @property
    def ok(self) -> bool:
        """Whether the difference is within the tolerance."""
        return abs(self.difference) <= self.tolerance


#: Tolerances of the foundation issue: Table B.1 cells 0.2 mm, B.2 cells 0.6 mm, frequencies
#: 1 %, the 6.5 kg model deflection 2 % and the analytic one (B.3) 0.5 %.
TABLE_B1_TOLERANCE_M = 0.2e-3
TABLE_B2_TOLERANCE_M = 0.6e-3
FREQUENCY_TOLERANCE = 0.01
STATIC_MODEL_TOLERANCE = 0.02
STATIC_ANALYTIC_TOLERANCE = 0.005


def compare_with_paper(result: Reproduction, paper: PaperNumbers) -> list[Comparison]:
    """Pairs every reproduced number with the paper's and the tolerance it must meet."""
    rows: list[Comparison] = []
    for label, ours, theirs, tol in (
        ('B.1', result.table_b1, paper.table_b1, TABLE_B1_TOLERANCE_M),
        ('B.2', result.table_b2, paper.table_b2, TABLE_B2_TOLERANCE_M),
    ):
        for mine, reported in zip(ours, theirs, strict=True):
            for column in ('uniform_m', 'loaded_m', 'end_load_m'):
                rows.append(
                    Comparison(
                        f'{label} n_s={mine.n_s} {column[:-2]}',
                        getattr(mine, column),
                        getattr(reported, column),
                        tol,
                        relative=False,
                    )
                )
    for key, scalar in (
        ('analytic', 'f_model_analytic_hz'),
        ('identified', 'f_model_identified_hz'),
        ('validation', 'f_validation_model_hz'),
    ):
        rows.append(
            Comparison(
                f'frequency {key}',
                result.frequencies_hz[key],
                paper.scalars[scalar],
                FREQUENCY_TOLERANCE,
                relative=True,
            )
        )
    rows.append(
        Comparison(
            'static 6.5 kg model',
            result.static_6p5kg_m['model'],
            paper.scalars['static_6p5kg_model_m'],
            STATIC_MODEL_TOLERANCE,
            relative=True,
        )
    )
    rows.append(
        Comparison(
            'static 6.5 kg analytic (B.3)',
            result.static_6p5kg_m['analytic'],
            paper.scalars['static_6p5kg_analytic_m'],
            STATIC_ANALYTIC_TOLERANCE,
            relative=True,
        )
    )
    return rows
