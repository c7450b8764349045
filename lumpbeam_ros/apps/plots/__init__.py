"""Figures, drawn with matplotlib on the Agg backend (no display needed)."""

__all__ = [
    'analysis',
    'arm',
    'beam',
    'comparison',
    'demo',
    'diagnosis',
    'files',
    'lines',
    'shaping',
]
