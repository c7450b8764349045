"""Model-discrepancy diagnosis: residual signatures, candidate effects, scores."""
