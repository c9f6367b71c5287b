"""Lessons: the formulas the notebooks derive, each reading as its formula in the notebook's symbols.

Imports only the mesh core and the numerical machinery.
"""
