"""The diagnosis node's parameters (values in ``config/diagnosis.yaml``, documented there)."""

from __future__ import annotations

from lumpbeam_ros.interface import DIAGNOSIS_NODE, SIMULATOR_NODE
from lumpbeam_ros.params.schema import Bounds, ParameterSchema, ParameterSpec

_POSITIVE = Bounds(0.0, low_open=True)

DIAGNOSIS_SCHEMA = ParameterSchema(
    node=DIAGNOSIS_NODE,
    summary=(
        'The discrepancy workflow of `lumpbeam diagnose` run live on each completed ring-down '
        '(or window) of /tip_pose and /tip_load, publishing /model_discrepancy; with adopt, '
        "the effects it finds go to the simulator node's parameters."
    ),
    config_file='diagnosis.yaml',
    parameters=(
        ParameterSpec(
            'trigger',
            'string',
            'ring_down',
            'ring_down: diagnose each load change once its decay is complete; window: '
            'diagnose every window_s of data (it must hold a load change)',
            choices=('ring_down', 'window'),
        ),
        ParameterSpec(
            'ring_down.pre_release_s',
            'double',
            1.0,
            'rest before the load change that a ring-down includes',
            's',
            _POSITIVE,
        ),
        ParameterSpec(
            'ring_down.decay_s',
            'double',
            8.0,
            'a ring-down is complete once the decay has lasted this long (at least 2 s of '
            'poses at 180 Hz are needed after the change)',
            's',
            Bounds(2.0, 600.0),
        ),
        ParameterSpec(
            'ring_down.min_amplitude_m',
            'double',
            0.0,
            'a ring-down is complete earlier once the tip z swings less than this (half '
            'peak-to-peak over the last 0.5 s); 0: only decay_s ends it',
            'm',
            Bounds(0.0, 1.0),
        ),
        ParameterSpec(
            'window_s',
            'double',
            10.0,
            'length of a window (trigger window)',
            's',
            Bounds(2.0, 600.0),
        ),
        ParameterSpec(
            'keep_s',
            'double',
            60.0,
            'the node keeps this much of the latest data (longer than any ring-down)',
            's',
            Bounds(5.0, 3600.0),
        ),
        ParameterSpec(
            'worker',
            'string',
            'process',
            'where a diagnosis runs: process (a worker process, the callbacks stay free) or '
            'thread (shares the interpreter)',
            choices=('process', 'thread'),
        ),
        ParameterSpec(
            'adopt',
            'bool',
            False,
            "hand the effects found to the simulator's parameters "
            '(effects.<name>.<parameter>) when the augmented model fits better than the '
            "simulator's current prediction",
            read_only=False,
        ),
        ParameterSpec(
            SIMULATOR_NODE,
            'string',
            SIMULATOR_NODE,
            'the node whose parameters adopt sets',
        ),
        ParameterSpec(
            'status_period_s',
            'double',
            1.0,
            'how often /model_discrepancy repeats the latest status',
            's',
            Bounds(0.05, 60.0),
        ),
        ParameterSpec(
            'beam_config',
            'string',
            '',
            "nominal beam file (as config/paper_beam.yaml); empty: the package's paper_beam.yaml",
        ),
        ParameterSpec(
            'hardware_id', 'string', 'beam', 'DiagnosticStatus.hardware_id of /model_discrepancy'
        ),
    ),
)
