"""The identifier's settings and their parameter file, ``config/identifier.yaml``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from lumpbeam_ros.errors import ConfigError
from lumpbeam_ros.paramfile import (
    check_known_keys,
    get_choice,
    get_float,
    get_int,
    read_parameter_file,
)
from lumpbeam_ros.resources import config_path


@dataclass(frozen=True)
class IdentifierConfig:
    """Settings of the window, the release detection, the fits and the quality checks.

    Each field is documented at its key in ``config/identifier.yaml``; the key is the field's
    entry in :data:`PARAMETER_KEYS`.
    """

    window_s: float = 10.0
    max_rate_hz: float = 400.0
    reset_jump_back_s: float = 1.0
    max_gap_s: float = 1.0
    publish_rate_hz: float = 2.0
    assumed_load_kg: float = 4.5
    min_step_snr: float = 20.0
    min_quiet_s: float = 0.2
    hint_late_s: float = 1.0
    hint_early_s: float = 1.0
    skip_after_release_s: float = 0.02
    max_modes: int = 2
    drift: bool = False
    nonlinear: str = 'auto'
    nonlinear_min_decay: float = 0.3
    recheck_every_s: float = 10.0
    max_fit_s: float = 60.0
    min_frequency_hz: float = 0.2
    max_frequency_hz: float = 40.0
    beam_mass_fraction: float = 0.2357
    min_samples: int = 50
    min_cycles: float = 3.0
    min_amplitude_snr: float = 5.0
    warn_rel_std_frequency: float = 0.01
    warn_rel_std_damping: float = 0.25
    warn_rel_std_stiffness: float = 0.05
    warn_cross_check_damping: float = 0.5
    min_release_confidence: float = 0.5


#: Field name -> dotted ROS parameter name.
PARAMETER_KEYS: dict[str, str] = {
    'window_s': 'window.length_s',
    'max_rate_hz': 'window.max_rate_hz',
    'reset_jump_back_s': 'window.reset_jump_back_s',
    'max_gap_s': 'window.max_gap_s',
    'publish_rate_hz': 'publish_rate_hz',
    'assumed_load_kg': 'release.assumed_load_kg',
    'min_step_snr': 'release.min_step_snr',
    'min_quiet_s': 'release.min_quiet_s',
    'hint_late_s': 'release.hint_late_s',
    'hint_early_s': 'release.hint_early_s',
    'skip_after_release_s': 'fit.skip_after_release_s',
    'max_modes': 'fit.max_modes',
    'drift': 'fit.drift',
    'nonlinear': 'fit.nonlinear',
    'nonlinear_min_decay': 'fit.nonlinear_min_decay',
    'recheck_every_s': 'fit.recheck_every_s',
    'max_fit_s': 'fit.max_duration_s',
    'min_frequency_hz': 'fit.min_frequency_hz',
    'max_frequency_hz': 'fit.max_frequency_hz',
    'beam_mass_fraction': 'effective_mass.beam_fraction',
    'min_samples': 'quality.min_samples',
    'min_cycles': 'quality.min_cycles',
    'min_amplitude_snr': 'quality.min_amplitude_snr',
    'warn_rel_std_frequency': 'quality.warn_rel_std_frequency',
    'warn_rel_std_damping': 'quality.warn_rel_std_damping',
    'warn_rel_std_stiffness': 'quality.warn_rel_std_stiffness',
    'warn_cross_check_damping': 'quality.warn_cross_check_damping',
    'min_release_confidence': 'quality.min_release_confidence',
}

#: Choices of ``fit.nonlinear``.
NONLINEAR_CHOICES = ('auto', 'always', 'never')

# Values that may be zero; every other float must be positive.
_NON_NEGATIVE = frozenset({'skip_after_release_s', 'min_step_snr', 'min_amplitude_snr'})
_FRACTIONS = frozenset({'beam_mass_fraction', 'min_release_confidence'})


def config_from_parameters(params: Mapping[str, Any], source: str | Path) -> IdentifierConfig:
    """Builds and validates the settings from flat (dotted) ROS parameters.

    Missing keys take the defaults of :class:`IdentifierConfig`.

    Args:
        params: Flat parameters, from a file or from a node's declared parameters.
        source: Where they came from, for error messages.

    Returns:
        The settings.

    Raises:
        ConfigError: An unknown key, a wrong type or a value out of range, naming the key.
    """
    check_known_keys(params, frozenset(PARAMETER_KEYS.values()), source)
    defaults = IdentifierConfig()
    values: dict[str, Any] = {}
    for f in fields(IdentifierConfig):
        key = PARAMETER_KEYS[f.name]
        default = getattr(defaults, f.name)
        value: str | bool | int | float
        if isinstance(default, str):
            value = get_choice(params, key, source, NONLINEAR_CHOICES, default)
        elif isinstance(default, bool):
            value = params.get(key, default)
            if not isinstance(value, bool):
                raise ConfigError(source, key, f'must be true or false, got {value!r}')
        elif isinstance(default, int):
            value = get_int(params, key, source, default, minimum=1)
        else:
            value = get_float(
                params,
                key,
                source,
                default,
                positive=f.name not in _NON_NEGATIVE,
                non_negative=f.name in _NON_NEGATIVE,
            )
            if f.name in _FRACTIONS and value > 1.0:
                raise ConfigError(source, key, f'must be at most 1, got {value!r}')
        values[f.name] = value
    if values['max_modes'] > 2:
        raise ConfigError(source, PARAMETER_KEYS['max_modes'], 'must be 1 or 2')
    if values['min_frequency_hz'] >= values['max_frequency_hz']:
        raise ConfigError(
            source, PARAMETER_KEYS['max_frequency_hz'], 'must exceed fit.min_frequency_hz'
        )
    return IdentifierConfig(**values)


def config_to_parameters(config: IdentifierConfig) -> dict[str, Any]:
    """Returns the flat ROS parameters that read back as ``config`` (for declaring them)."""
    return {PARAMETER_KEYS[f.name]: getattr(config, f.name) for f in fields(IdentifierConfig)}


def load_identifier_config(path: str | Path | None = None) -> IdentifierConfig:
    """Reads an identifier parameter file (default: the package's ``config/identifier.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The settings.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    path = config_path('identifier.yaml') if path is None else Path(path)
    return config_from_parameters(read_parameter_file(path), path)
