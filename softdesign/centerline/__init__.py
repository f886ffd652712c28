"""Centerlines from a vessel surface alone, as VMTK's ``vmtkcenterlines`` computes them.

closing.py   check the surface, cap its openings (their centres are endpoints), orient it outwards
voronoi.py   the internal Voronoi diagram: circumcentres inside, their inscribed-sphere radii, the graph
endpoints.py openings, labelled caps, flat caps or the graph's extremities; which end is the inlet
paths.py     least-cost (integral of 1/R) paths by Dijkstra, smoothed and resampled
ends.py      each path continued straight from the Voronoi diagram to its openings' centres
extract.py   the whole: surface in, one path per outlet out

No files, no printing (the command is :mod:`softdesign.cli.centerline`, the
writer :mod:`softdesign.io.centerline_vtp`).
"""
