"""The lumped-parameter beam: parameters, statics, dynamics, modes, scenarios."""
