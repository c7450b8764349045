"""The flexible arm from data: its moves, the modes of its ring-downs, its links fitted."""

__all__ = [
    'bag_modes',
    'link_fit',
    'moves',
]
