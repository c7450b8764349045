"""Joint motion commanded to an arm: the joint trajectory and its file."""
