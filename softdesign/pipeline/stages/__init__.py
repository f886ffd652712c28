"""The stages of a build, in order; each module owns one (its STAGE: run, write, load, describe).

ingest -> blend -> links -> kinematics -> fit -> export (DESIGN.md's five
stages, with the link breaks a product of their own between blend and
kinematics: both kinematics and the fit consume them) -> mould (a casting
mould of the q = 0 body, when the case asks for one) -> volume_mesh (tetrahedra of
the body for simulators, when asked for) -> feasibility (skin
stretch and wall thickness, judged against the case's material).

The list of them in build order is :data:`softdesign.pipeline.stage_order.STAGES`.  This package imports
nothing, so that importing one stage (the report loads six stages' results) does not import all nine and the
libraries they compute with.
"""
