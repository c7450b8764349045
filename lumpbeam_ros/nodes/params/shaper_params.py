"""The shaper node's parameters (values in ``config/shaper.yaml``, documented there)."""

from __future__ import annotations

from lumpbeam_ros.base.interface import SHAPER_NODE
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.core.shaping.choices import DEFAULT_MAX_MODES, SHAPER_NAMES

SHAPER_SCHEMA = ParameterSchema(
    node=SHAPER_NODE,
    summary=(
        'Input shaping live: each /joint_trajectory convolved with a shaper (ZV, ZVD, EI, '
        'several modes) and published on /joint_trajectory_shaped, its modes taken from '
        '/beam_params or fixed by parameters.'
    ),
    config_file='shaper.yaml',
    parameters=(
        ParameterSpec(
            'source',
            'string',
            'beam_params',
            'beam_params: the modes identified live on /beam_params; parameters: one mode '
            'fixed by frequency_hz and damping_ratio; model: each trajectory shaped for the '
            "modes of arm_config's model at its end, with the latest links on /arm_params",
            choices=('beam_params', 'parameters', 'model'),
        ),
        ParameterSpec(
            'arm_config',
            'string',
            '',
            'arm file (as config/arm_3link.yaml) of source model: its values until /arm_params '
            'gives identified ones',
        ),
        ParameterSpec(
            'tune',
            'bool',
            False,
            "source model: tune each move's impulses on the model's simulation of it (about a "
            'second of CPU per move)',
        ),
        ParameterSpec(
            'frequency_hz',
            'double',
            1.0,
            'natural frequency of the mode to cancel (source parameters)',
            'Hz',
            Bounds(0.0, low_open=True),
        ),
        ParameterSpec(
            'damping_ratio',
            'double',
            0.0,
            'damping ratio of the mode to cancel (source parameters)',
            '',
            Bounds(0.0, 1.0, high_open=True),
        ),
        ParameterSpec(
            'shaper',
            'string',
            'zv',
            'the shaper for well-known frequencies (and for sources parameters and model)',
            choices=SHAPER_NAMES,
        ),
        ParameterSpec(
            'robust_shaper',
            'string',
            'ei',
            'the shaper when an identified frequency is uncertain (see robust_above)',
            choices=('zvd', 'ei'),
        ),
        ParameterSpec(
            'robust_above',
            'double',
            0.01,
            'relative standard deviation of an identified frequency (std / value) above which '
            'robust_shaper replaces shaper; ZV leaves at most 5 % within about 3 % of its '
            'frequency, so 0.01 keeps a 3-sigma error in that band; 0: always robust',
            '',
            Bounds(0.0, 1.0),
        ),
        ParameterSpec(
            'max_modes',
            'int',
            DEFAULT_MAX_MODES,
            'cancel at most this many identified modes (the first ones, by frequency)',
            '',
            Bounds(1, 8),
        ),
        ParameterSpec(
            'max_added_s',
            'double',
            10.0,
            'refuse a shaper that would make each move longer than this (a mode too slow, '
            'e.g. a mis-scaled estimate); the last good one is kept',
            's',
            Bounds(0.0, 3600.0, low_open=True),
        ),
        ParameterSpec(
            'max_command_s',
            'double',
            600.0,
            'drop a /joint_trajectory lasting longer than this (its shaped copy is sampled at '
            '1 kHz throughout)',
            's',
            Bounds(0.0, 86400.0, low_open=True),
        ),
        ParameterSpec(
            'unshaped_until_estimate',
            'bool',
            False,
            'until the first valid estimate (source model: the first identified arm, the '
            "file's model unused), publish each trajectory unshaped (with a warning) instead "
            'of nothing',
        ),
    ),
)
