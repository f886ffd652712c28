"""Hyperelastic finite elements of a section: material laws, assembly, follower pressure, Newton with load steps.

A pure numeric layer (numpy, scipy, pymetis for the factorizations' order): no files, no printing.  Its
vectorised assembly is checked against scikit-fem's (tests/mechanics/test_against_scikit_fem.py).  Units
are mm, kPa (= mN/mm^2) and mN; a pressure is in kPa.
"""
