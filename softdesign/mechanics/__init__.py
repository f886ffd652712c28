"""Hyperelastic finite elements of a section: material laws, assembly, follower pressure, Newton with load steps.

A pure numeric layer (numpy, scipy, scikit-fem): no files, no printing.  Units
are mm, kPa (= mN/mm^2) and mN; a pressure is in kPa.
"""
