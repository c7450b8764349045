"""Model-discrepancy diagnosis (doc/interfaces.md): residual signatures, candidate effects, scores.

Where a simulation and a measurement disagree, which physics is missing? The nominal beam and
the nominal beam plus each effect of doc/interfaces.md are fitted to a drop-test record (tip z
and pitch under the ``/tip_load`` events) by least squares on the modal simulator, scored by
an information criterion and on a held-out part of the record, and the winner is named only
when the data insist on it; otherwise the answer is ``none`` or ``unexplained``.

Use::

    from lumpbeam_ros.core.diagnose.measurement import read_record
    from lumpbeam_ros.core.diagnose.workflow import diagnose

    result = diagnose(read_record('drop_bag'), beam)
    result.missing_effect, result.effect_parameters     # e.g. 'coulomb_friction', {...}
    result.gap_before, result.gap_after                 # Gap(rms_m, max_m, ...)
    result.as_dict()                                    # the JSON of ``lumpbeam diagnose``

Modules: :mod:`.measurement` (the input: the measured record), :mod:`.noise` (sigma from the data),
:mod:`.candidates` (the models and their parameter ranges), :mod:`.fitting` (least
squares), :mod:`.gap` (residual size, frequency and damping errors), :mod:`.signatures`
(envelope shape, frequency drift, time shift, slope ratio, static offsets),
:mod:`.scoring` (BIC, held-out check, the decision), :mod:`.workflow` (all of it in order).
"""

__all__ = [
    'candidates',
    'fitting',
    'gap',
    'live',
    'measurement',
    'noise',
    'scoring',
    'selection',
    'signatures',
    'workflow',
]
