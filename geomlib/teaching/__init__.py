"""Teaching aids: 3D views and stills, exercise checks, notebook helpers, experiment drivers.

May import every other layer; no other layer imports it.
"""
