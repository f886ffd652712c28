"""Vessels the project generates itself: the sample vessel, the sample cohort and the benchmark tube.

They are test and demo inputs, not part of the product: geometry in
:mod:`~softdesign.samples.sample_vessel`, :mod:`~softdesign.samples.cohort_vessels`
and :mod:`~softdesign.samples.synthetic_vessel`; their capped walls in
:mod:`~softdesign.samples.surfaces`; VMTK-style files in :mod:`~softdesign.samples.files`.
"""
