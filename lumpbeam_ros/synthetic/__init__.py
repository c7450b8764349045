"""Synthetic experiments: the paper's drop test simulated and written as a bag."""
