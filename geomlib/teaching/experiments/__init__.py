"""Experiment drivers: the step a reader gives and its unit, the smoothing sweep and the denoising comparison of notebook 07."""
