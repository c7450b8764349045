"""Identification of stiffness, frequency and damping from tip oscillations."""
