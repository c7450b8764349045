"""Input shaping: impulse sequences that cancel a flexible arm's modes, applied to commands."""

__all__ = [
    'apply',
    'choices',
    'estimate',
    'extra_insensitive',
    'impulses',
    'limits',
    'loop',
    'modes_file',
    'shapers',
    'tune',
    'vibration',
    'workspace',
]
