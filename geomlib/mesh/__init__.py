"""The mesh core: errors, validation at the door, topology, geometry, reading and writing files.

Imports no other layer of geomlib.
"""
