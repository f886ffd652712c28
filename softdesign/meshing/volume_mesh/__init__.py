"""Tetrahedral meshes of the body for simulators: the swept mesher (one cross-section swept along l and mapped to
every q, with its strain) and fTetWild, with the checks and quality figures of both."""
