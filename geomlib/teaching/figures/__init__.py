"""Figures: the matplotlib pictures the notebooks show (angle fans, cotangent diagrams, normal curvature plots, convergence plots)."""
