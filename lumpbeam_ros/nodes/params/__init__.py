"""The nodes' declared parameters: the schema type, one schema per node and the reference."""

__all__ = [
    'camera_params',
    'diagnosis_params',
    'identifier_params',
    'reference',
    'shaper_params',
    'simulator_params',
]
