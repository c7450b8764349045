"""The identifier's settings, each field a declared parameter (``config/identifier.yaml``).

The node's parameters (:mod:`lumpbeam_ros.nodes.params.identifier_params`), the checks of a
parameter file, the file itself (a test holds it equal) and ``doc/parameters.md`` all come from
the fields below.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.paramfile import check_known_keys, parameter_file
from lumpbeam_ros.base.schema import (
    Bounds,
    setting,
    settings_from_parameters,
    settings_specs,
    settings_to_parameters,
)

_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)
_FRACTION = Bounds(0.0, 1.0, low_open=True)

#: The most modes ``fit.max_modes`` (and ``lumpbeam analyze --max-modes``) may ask for: a
#: camera at 180 fps sees a beam's first few modes, not ten.
MAX_MODES_LIMIT = 8
#: Choices of ``fit.nonlinear``.
NONLINEAR_CHOICES = ('auto', 'always', 'never')


@dataclass(frozen=True)
class IdentifierConfig:
    """Settings of the window, the release detection, the fits and the quality checks.

    Each field is a parameter: its name, default, range, unit and description are written
    where it is declared (and ``config/identifier.yaml`` says more at its key).
    """

    window_s: float = setting(
        'window.length_s', 10.0, 'length of the sliding window analysed', 's', _POSITIVE
    )
    max_rate_hz: float = setting(
        'window.max_rate_hz',
        400.0,
        'highest pose rate the window is sized for; faster input shortens the window',
        'Hz',
        _POSITIVE,
    )
    reset_jump_back_s: float = setting(
        'window.reset_jump_back_s',
        1.0,
        'a stamp this far before the newest one empties the window (a bag looping)',
        's',
        _POSITIVE,
    )
    max_gap_s: float = setting(
        'window.max_gap_s',
        1.0,
        'a record whose pose stamps pause or jump ahead by more than this is split there; '
        'analysis keeps the stretch that holds the release and names the rest',
        's',
        _POSITIVE,
    )
    publish_rate_hz: float = setting(
        'publish_rate_hz', 2.0, 'how often /beam_params is published', 'Hz', Bounds(0.01, 100.0)
    )
    assumed_load_kg: float = setting(
        'release.assumed_load_kg',
        4.5,
        "load assumed to be dropped when /tip_load is absent (the paper's m_l, B.3)",
        'kg',
        _POSITIVE,
    )
    min_step_snr: float = setting(
        'release.min_step_snr',
        20.0,
        'without /tip_load, a release is a rise of the static level of at least this '
        'many times the noise of the quiet stretch before it',
        bounds=_NON_NEGATIVE,
    )
    min_quiet_s: float = setting(
        'release.min_quiet_s',
        0.2,
        'the quiet stretch before a release found in the data lasts at least this long',
        's',
        _POSITIVE,
    )
    hint_late_s: float = setting(
        'release.hint_late_s',
        1.0,
        'a drop on /tip_load only hints that a release happened: the release is looked '
        'for in the poses from this long before the reading (a late reading) ...',
        's',
        _POSITIVE,
    )
    hint_early_s: float = setting(
        'release.hint_early_s',
        1.0,
        '... to this long after it (a reading sent before the load actually left)',
        's',
        _POSITIVE,
    )
    skip_after_release_s: float = setting(
        'fit.skip_after_release_s',
        0.02,
        'samples this soon after the release are left out of the decay fit',
        's',
        _NON_NEGATIVE,
    )
    max_modes: int = setting(
        'fit.max_modes',
        3,
        'damped modes the least-squares model may hold: each mode after the first is kept '
        'only when it stands out of the noise (fit.mode_false_alarm)',
        bounds=Bounds(1, MAX_MODES_LIMIT),
    )
    mode_false_alarm: float = setting(
        'fit.mode_false_alarm',
        1e-3,
        'a mode after the first is kept when its amplitude exceeds k of its standard '
        'deviations, k = sqrt(2 ln(N / this)) for N samples fitted: the chance that noise '
        'alone gives a mode',
        bounds=Bounds(0.0, 0.5, low_open=True),
    )
    drift: bool = setting(
        'fit.drift', False, 'add a linear drift to the decay model (a creeping mount)'
    )
    nonlinear: str = setting(
        'fit.nonlinear',
        'auto',
        "the first mode's level and frequency in proportion to the squared amplitude: "
        'auto fits them when the squared amplitude decays by fit.nonlinear_min_decay over '
        'the fit; always or never',
        choices=NONLINEAR_CHOICES,
    )
    nonlinear_min_decay: float = setting(
        'fit.nonlinear_min_decay',
        0.3,
        "auto's threshold: 2 sigma T, the decay exponent of the squared amplitude over the "
        'fitted stretch T',
        bounds=_POSITIVE,
    )
    shift_prior_std: float = setting(
        'fit.shift_prior_std',
        0.1,
        "the nonlinear fit's frequency shift is held to the beam model's backbone, give or "
        'take this fraction of it (a prior); 0 leaves the shift free. Not used for an arm',
        bounds=_NON_NEGATIVE,
    )
    recheck_every_s: float = setting(
        'fit.recheck_every_s',
        10.0,
        'the whole identification is redone at least this often in data time; between, '
        'each update restarts from the previous solution',
        's',
        _POSITIVE,
    )
    max_fit_s: float = setting(
        'fit.max_duration_s',
        60.0,
        'the decay fit stops this long after the release',
        's',
        _POSITIVE,
    )
    min_frequency_hz: float = setting(
        'fit.min_frequency_hz',
        0.2,
        "lowest frequency taken as the beam's first mode",
        'Hz',
        _POSITIVE,
    )
    max_frequency_hz: float = setting(
        'fit.max_frequency_hz',
        40.0,
        "highest frequency taken as the beam's first mode (above fit.min_frequency_hz)",
        'Hz',
        _POSITIVE,
    )
    rest_tolerance_rad: float = setting(
        'ring_down.rest_tolerance_rad',
        1e-5,
        'an arm (with /joint_states) is at rest while every joint stays within this of its '
        'angle when it stopped; the free vibration is fitted from that stop (for encoder '
        'readings, a few counts)',
        'rad',
        _POSITIVE,
    )
    beam_mass_fraction: float = setting(
        'effective_mass.beam_fraction',
        0.2357,
        "fraction of the beam's own mass moving with the tip in the first mode "
        "(Rayleigh's 33/140), for the stiffness implied by the frequency",
        bounds=_FRACTION,
    )
    min_samples: int = setting(
        'quality.min_samples',
        50,
        'fewer valid samples: status ERROR, no estimate',
        bounds=Bounds(1),
    )
    min_cycles: float = setting(
        'quality.min_cycles', 3.0, 'fewer fitted cycles: status WARN', bounds=_POSITIVE
    )
    min_amplitude_snr: float = setting(
        'quality.min_amplitude_snr',
        5.0,
        "the first mode's amplitude must be this many times the residual noise, else ERROR",
        bounds=_NON_NEGATIVE,
    )
    warn_rel_std_frequency: float = setting(
        'quality.warn_rel_std_frequency',
        0.01,
        "status WARN when the natural frequency's relative std exceeds this",
        bounds=_POSITIVE,
    )
    warn_rel_std_damping: float = setting(
        'quality.warn_rel_std_damping',
        0.25,
        "status WARN when the damping ratio's relative std exceeds this",
        bounds=_POSITIVE,
    )
    warn_rel_std_stiffness: float = setting(
        'quality.warn_rel_std_stiffness',
        0.05,
        "status WARN when k_tE's relative std exceeds this",
        bounds=_POSITIVE,
    )
    warn_cross_check_damping: float = setting(
        'quality.warn_cross_check_damping',
        0.5,
        'status WARN when the matrix-pencil damping ratio differs from the fitted one by '
        'more than this fraction',
        bounds=_POSITIVE,
    )
    min_release_confidence: float = setting(
        'quality.min_release_confidence',
        0.5,
        'status WARN when the release found in the data has a lower confidence',
        bounds=_FRACTION,
    )

    def relation_problem(self) -> tuple[str, str] | None:
        """What the values break together: ``(key, problem)``, or ``None``."""
        if self.min_frequency_hz >= self.max_frequency_hz:
            return 'fit.max_frequency_hz', 'must exceed fit.min_frequency_hz'
        return None


#: The parameters of ``config/identifier.yaml``, in the order of the fields.
IDENTIFIER_SETTINGS = settings_specs(IdentifierConfig)


def config_from_parameters(params: Mapping[str, Any], source: str | Path) -> IdentifierConfig:
    """Builds and validates the settings from flat (dotted) ROS parameters.

    Missing keys take the fields' defaults.

    Args:
        params: Flat parameters, from a file or from a node's declared parameters.
        source: Where they came from, for error messages.

    Returns:
        The settings.

    Raises:
        ConfigError: An unknown key, a wrong type or a value out of range, naming the key.
    """
    check_known_keys(params, frozenset(spec.name for spec in IDENTIFIER_SETTINGS), source)
    return settings_from_parameters(IdentifierConfig, params, source)


def with_max_modes(config: IdentifierConfig, text: str) -> IdentifierConfig:
    """The settings with ``fit.max_modes`` from a command line's ``--max-modes``.

    Args:
        config: The settings.
        text: The option's value as typed.

    Returns:
        The settings with that many modes at most.

    Raises:
        LumpbeamError: Not a whole number within the parameter's bounds, naming the option.
    """
    spec = next(spec for spec in IDENTIFIER_SETTINGS if spec.name == 'fit.max_modes')
    value: object
    try:
        value = int(text)
    except ValueError:
        value = text
    problem = spec.problem(value)
    if problem:
        raise LumpbeamError(f'--max-modes: {problem}')
    return replace(config, max_modes=int(text))


def config_to_parameters(config: IdentifierConfig) -> dict[str, Any]:
    """Returns the flat ROS parameters that read back as ``config`` (for declaring them)."""
    return settings_to_parameters(config)


def load_identifier_config(path: str | Path | None = None) -> IdentifierConfig:
    """Reads an identifier parameter file (default: the package's ``config/identifier.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The settings.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    source, params = parameter_file(path, 'identifier.yaml')
    return config_from_parameters(params, source)
