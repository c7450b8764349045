"""The flexible arm from data: its moves, the modes of its ring-downs, its links and payload."""

__all__ = [
    'bag_modes',
    'learner',
    'link_fit',
    'moves',
    'payload_fit',
]
