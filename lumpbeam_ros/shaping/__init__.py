"""Input shaping: impulse sequences that cancel a flexible arm's modes, applied to commands."""
