"""The material math of a continuum, pure numpy: hyperelastic laws and the strain and stress of an element.

Below both the meshes (:mod:`softdesign.meshing`, which measures the morph's strain on its volume mesh) and the
finite elements (:mod:`softdesign.mechanics`, which solve with the same laws): it imports neither.  Units are mm and
kPa.
"""
