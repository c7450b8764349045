"""The diagnosis node's parameters (values in ``config/diagnosis.yaml``, documented there).

When a diagnosis runs: the fields of :class:`~lumpbeam_ros.core.diagnose.live.LiveDiagnosisConfig`,
declared there once; the rest is the node's own.
"""

from __future__ import annotations

from lumpbeam_ros.base.interface import DIAGNOSIS_NODE, SIMULATOR_NODE
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec, settings_specs
from lumpbeam_ros.core.diagnose.live import LiveDiagnosisConfig

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
        *settings_specs(LiveDiagnosisConfig),
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
