"""Camera side: the checkerboard, the synthetic camera, and the tip tracker."""
