"""The identifier node's parameters: its settings (``config/identifier.yaml``) and its own.

The settings are :class:`~lumpbeam_ros.core.ident.settings.IdentifierConfig`'s fields, each
declared there once.
"""

from __future__ import annotations

from lumpbeam_ros.base.interface import IDENTIFIER_NODE
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.core.ident.settings import IDENTIFIER_SETTINGS
from lumpbeam_ros.nodes.realtime import REALTIME_PRIORITY

#: The parameters that are not identification settings (not in config/identifier.yaml).
_NODE = (
    ParameterSpec(
        'beam_config',
        'string',
        '',
        "beam parameter file (as config/paper_beam.yaml); empty: the package's paper_beam.yaml",
    ),
    ParameterSpec('hardware_id', 'string', 'beam', 'DiagnosticStatus.hardware_id of /beam_params'),
    ParameterSpec(
        'arm_config',
        'string',
        '',
        'arm file (as config/arm_3link.yaml): given, the links are fitted again after every '
        "ring-down, from the file's values, and published on /arm_params; empty: no arm fit",
    ),
    ParameterSpec(
        'fit_payload',
        'bool',
        False,
        'with arm_config: fit the payload mass instead of the links (the links as the file '
        'gives them)',
    ),
    ParameterSpec(
        'arm_fit_after_s',
        'double',
        3.0,
        "with arm_config: a ring-down's modes join the arm's fit once the joints have been at "
        'rest this long',
        's',
        Bounds(0.1, 600.0),
    ),
    REALTIME_PRIORITY,
)

IDENTIFIER_SCHEMA = ParameterSchema(
    node=IDENTIFIER_NODE,
    summary=(
        'Frequency, damping and stiffness from the tip oscillations after a load drop '
        '(paper section B.3.2, eqs. B.12 and B.20-B.22), published on /beam_params. '
        'Every parameter is read-only: set it in the params file or with -p.'
    ),
    config_file='identifier.yaml',
    parameters=(*IDENTIFIER_SETTINGS, *_NODE),
)

#: The parameters that are not identification settings (not in config/identifier.yaml).
NODE_ONLY = tuple(spec.name for spec in _NODE)
