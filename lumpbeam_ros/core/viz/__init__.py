"""What a viewer draws: the beam as markers, their messages and the live view to Foxglove."""

__all__ = [
    'arm_scenes',
    'layouts',
    'marker_messages',
    'markers',
]
