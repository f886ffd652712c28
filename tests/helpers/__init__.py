"""Shared test helpers: paths, small synthetic cases, analytic curves and bodies, seed formulas."""
