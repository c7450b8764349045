"""The identifier node's parameters (values in ``config/identifier.yaml``, documented there).

The identification settings are :class:`~lumpbeam_ros.ident.settings.IdentifierConfig`'s
fields under their :data:`~lumpbeam_ros.ident.settings.PARAMETER_KEYS`; a test holds the two
and the file equal.
"""

from __future__ import annotations

from lumpbeam_ros.ident.settings import NONLINEAR_CHOICES
from lumpbeam_ros.interface import IDENTIFIER_NODE
from lumpbeam_ros.params.schema import Bounds, ParameterSchema, ParameterSpec

_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)
_FRACTION = Bounds(0.0, 1.0, low_open=True)


def _double(name: str, default: float, description: str, unit: str = '') -> ParameterSpec:
    return ParameterSpec(name, 'double', default, description, unit, _POSITIVE)


IDENTIFIER_SCHEMA = ParameterSchema(
    node=IDENTIFIER_NODE,
    summary=(
        'Frequency, damping and stiffness from the tip oscillations after a load drop '
        '(paper section B.3.2, eqs. B.12 and B.20-B.22), published on /beam_params. '
        'Every parameter is read-only: set it in the params file or with -p.'
    ),
    config_file='identifier.yaml',
    parameters=(
        _double('window.length_s', 10.0, 'length of the sliding window analysed', 's'),
        _double(
            'window.max_rate_hz',
            400.0,
            'highest pose rate the window is sized for; faster input shortens the window',
            'Hz',
        ),
        _double(
            'window.reset_jump_back_s',
            1.0,
            'a stamp this far before the newest one empties the window (a bag looping)',
            's',
        ),
        _double(
            'window.max_gap_s',
            1.0,
            'a record whose pose stamps pause or jump ahead by more than this is split there; '
            'analysis keeps the stretch that holds the release and names the rest',
            's',
        ),
        ParameterSpec(
            'publish_rate_hz',
            'double',
            2.0,
            'how often /beam_params is published',
            'Hz',
            Bounds(0.01, 100.0),
        ),
        _double(
            'release.assumed_load_kg',
            4.5,
            "load assumed to be dropped when /tip_load is absent (the paper's m_l, B.3)",
            'kg',
        ),
        ParameterSpec(
            'release.min_step_snr',
            'double',
            20.0,
            'without /tip_load, a release is a rise of the static level of at least this '
            'many times the noise of the quiet stretch before it',
            bounds=_NON_NEGATIVE,
        ),
        _double(
            'release.min_quiet_s',
            0.2,
            'the quiet stretch before a release found in the data lasts at least this long',
            's',
        ),
        _double(
            'release.hint_late_s',
            1.0,
            'a drop on /tip_load only hints that a release happened: the release is looked '
            'for in the poses from this long before the reading (a late reading) ...',
            's',
        ),
        _double(
            'release.hint_early_s',
            1.0,
            '... to this long after it (a reading sent before the load actually left)',
            's',
        ),
        ParameterSpec(
            'fit.skip_after_release_s',
            'double',
            0.02,
            'samples this soon after the release are left out of the decay fit',
            's',
            _NON_NEGATIVE,
        ),
        ParameterSpec(
            'fit.max_modes',
            'int',
            2,
            'damped modes the least-squares model may hold: 1, or 2 to also fit a second '
            'mode the matrix pencil finds above the noise',
            bounds=Bounds(1, 2),
        ),
        ParameterSpec(
            'fit.drift', 'bool', False, 'add a linear drift to the decay model (a creeping mount)'
        ),
        ParameterSpec(
            'fit.nonlinear',
            'string',
            'auto',
            "the first mode's level and frequency in proportion to the squared amplitude: "
            'auto fits them when the squared amplitude decays by fit.nonlinear_min_decay over '
            'the fit; always or never',
            choices=NONLINEAR_CHOICES,
        ),
        _double(
            'fit.nonlinear_min_decay',
            0.3,
            "auto's threshold: 2 sigma T, the decay exponent of the squared amplitude over the "
            'fitted stretch T',
        ),
        _double(
            'fit.recheck_every_s',
            10.0,
            'the whole identification is redone at least this often in data time; between, '
            'each update restarts from the previous solution',
            's',
        ),
        _double(
            'fit.max_duration_s', 60.0, 'the decay fit stops this long after the release', 's'
        ),
        _double(
            'fit.min_frequency_hz', 0.2, "lowest frequency taken as the beam's first mode", 'Hz'
        ),
        _double(
            'fit.max_frequency_hz',
            40.0,
            "highest frequency taken as the beam's first mode (above fit.min_frequency_hz)",
            'Hz',
        ),
        ParameterSpec(
            'effective_mass.beam_fraction',
            'double',
            0.2357,
            "fraction of the beam's own mass moving with the tip in the first mode "
            "(Rayleigh's 33/140), for the stiffness implied by the frequency",
            bounds=_FRACTION,
        ),
        ParameterSpec(
            'quality.min_samples',
            'int',
            50,
            'fewer valid samples: status ERROR, no estimate',
            bounds=Bounds(1),
        ),
        _double('quality.min_cycles', 3.0, 'fewer fitted cycles: status WARN'),
        ParameterSpec(
            'quality.min_amplitude_snr',
            'double',
            5.0,
            "the first mode's amplitude must be this many times the residual noise, else ERROR",
            bounds=_NON_NEGATIVE,
        ),
        _double(
            'quality.warn_rel_std_frequency',
            0.01,
            "status WARN when the natural frequency's relative std exceeds this",
        ),
        _double(
            'quality.warn_rel_std_damping',
            0.25,
            "status WARN when the damping ratio's relative std exceeds this",
        ),
        _double(
            'quality.warn_rel_std_stiffness',
            0.05,
            "status WARN when k_tE's relative std exceeds this",
        ),
        _double(
            'quality.warn_cross_check_damping',
            0.5,
            'status WARN when the matrix-pencil damping ratio differs from the fitted one by '
            'more than this fraction',
        ),
        ParameterSpec(
            'quality.min_release_confidence',
            'double',
            0.5,
            'status WARN when the release found in the data has a lower confidence',
            bounds=_FRACTION,
        ),
        ParameterSpec(
            'beam_config',
            'string',
            '',
            "beam parameter file (as config/paper_beam.yaml); empty: the package's "
            'paper_beam.yaml',
        ),
        ParameterSpec(
            'hardware_id', 'string', 'beam', 'DiagnosticStatus.hardware_id of /beam_params'
        ),
    ),
)

#: The parameters that are not identification settings (not in config/identifier.yaml).
NODE_ONLY = ('beam_config', 'hardware_id')
