"""Figures, drawn with matplotlib on the Agg backend (no display needed)."""
