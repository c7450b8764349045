"""Input shaping: impulse sequences that cancel a flexible arm's modes, applied to commands."""

__all__ = [
    'apply',
    'estimate',
    'extra_insensitive',
    'impulses',
    'loop',
    'modes_file',
    'shapers',
    'vibration',
]
