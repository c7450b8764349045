"""The camera's validation: the independent ray caster, the matrix, scoring against truth."""
