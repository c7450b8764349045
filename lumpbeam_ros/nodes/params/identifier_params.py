"""The identifier node's parameters: its settings (``config/identifier.yaml``) and its own.

The settings are :class:`~lumpbeam_ros.core.ident.settings.IdentifierConfig`'s fields, each
declared there once.
"""

from __future__ import annotations

from lumpbeam_ros.base.interface import IDENTIFIER_NODE
from lumpbeam_ros.base.schema import ParameterSchema, ParameterSpec
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
