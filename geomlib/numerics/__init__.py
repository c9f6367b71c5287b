"""Numerical machinery: sparse factorisations, eigensolvers, caches and progress bars.

Thin wrappers of scipy, CHOLMOD (cholespy) and tqdm; imports only the mesh core.
"""
