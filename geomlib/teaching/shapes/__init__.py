"""Exact shapes: the workbook's test and check meshes (plane, saddle, sphere, ellipsoid, torus) with their exact curvature."""
