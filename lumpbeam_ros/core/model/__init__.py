"""The lumped-parameter beam: parameters, statics, dynamics, modes, scenarios."""

__all__ = [
    'adopt',
    'chain',
    'hermite',
    'integrate',
    'modes',
    'parameters',
    'reproduce',
    'rules',
    'sensor',
    'simulate',
    'statics',
    'stream',
    'trajectory',
    'arm',
]
