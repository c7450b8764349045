"""Synthetic experiments: the paper's drop test simulated and written as a bag."""

__all__ = [
    'arm_bag',
    'campaign_bags',
    'drop_test',
    'images',
    'reference_sensor',
]
