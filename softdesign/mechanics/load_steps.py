"""How a reinforced solid's pressures are stepped from rest: the first step's size and the path's tolerance.

Both rules serve :func:`~softdesign.mechanics.newton.solve_pressures` for the
whole device (:mod:`softdesign.mechanics.device`) and for one reinforced
section (:func:`softdesign.mechanics.section.simulate_section`).

The first step
    From rest Newton's first iterate is the linear answer.  A hoop thread
    ``1e3``-``1e5`` times stiffer than the wall it lines is nearly a
    constraint, and the linear answer meets it only to first order: the wall's
    rotations stretch the thread at second order, a strain hundreds of times
    the linearized one (on the demo's section 1 at 10 kPa in one chamber the
    first iterate's thread strain reached 2.7e-2 where its linearization read
    5e-5), and that strain times the thread's stiffness is the next residual.
    Newton recovers from it only when the step is small: past about a tenth
    of the silicone's shear modulus the first step fails and is halved, each
    failure costing up to ``max_iterations`` factorizations.  So the first
    step's largest pressure is at most ``FIRST_STEP_MU`` shear moduli, in the
    fewest power-of-two steps that get there; a step that converges easily
    doubles the next.  Measured on the sample single-supply device from rest:
    steps of 0.07 and 0.09 mu converged (9 and 10 iterations), 0.14 and 0.18
    mu failed after 12 (at P*, four halvings from the default first step, 1/8
    of 11.3 mu: 23 factorizations, 7 % of the solve); on the per-chamber
    demo's section 1 at 20 kPa in one chamber (0.51 mu) the default two steps
    failed at 10 kPa after 12 iterations and the solve took 36
    factorizations, the rule's eight (2.5 kPa first) 21.
The path's tolerance
    A hyperelastic solid's equilibrium does not depend on the path to it, so
    the equilibria of the steps before the last only start the next step:
    they converge to ``PATH_RTOL`` of their pressure load, the last to the
    settings' ``rtol`` (1e-8).  Measured on the sample device at P*: 307
    factorizations against 336, its figures moved by 3e-7 mm.
"""

from __future__ import annotations

import math
from dataclasses import replace

from softdesign.mechanics.newton import NewtonSettings

#: The first load step's largest pressure, in shear moduli of the silicone (see the module's docstring).
FIRST_STEP_MU = 0.1
#: The tolerance of the load steps before the last, relative to their pressure load (NewtonSettings.path_rtol).
PATH_RTOL = 1e-4


def first_steps(load_steps: int, largest_kpa: float, mu_kpa: float) -> int:
    """``load_steps``, or more (a power of two) so that the first step's largest pressure is at most FIRST_STEP_MU
    shear moduli; a converged easy step doubles the next (:func:`~softdesign.mechanics.newton.solve_pressures`)."""
    needed = largest_kpa / (FIRST_STEP_MU * mu_kpa)
    return max(load_steps, 2 ** math.ceil(math.log2(needed)) if needed > 1.0 else 1)


def first_step_settings(settings: NewtonSettings, largest_kpa: float, mu_kpa: float) -> NewtonSettings:
    """``settings`` with :func:`first_steps`'s load steps and as many fewer halvings, so that the smallest step,
    ``1 / (load_steps 2^max_cutbacks)`` of the load, is the one asked or at most half of it (more steps to start
    with and the same halvings would let a solve that cannot go on creep further before it stops)."""
    steps = first_steps(settings.load_steps, largest_kpa, mu_kpa)
    fewer = int(math.floor(math.log2(steps / settings.load_steps)))
    return replace(settings, load_steps=steps, max_cutbacks=max(0, settings.max_cutbacks - fewer))


def stepped_from_rest(settings: NewtonSettings, largest_kpa: float, mu_kpa: float) -> NewtonSettings:
    """``settings`` for a solve from rest to pressures whose largest is ``largest_kpa``: the first step's rule
    (:func:`first_step_settings`) and, unless the settings give one, PATH_RTOL for the steps before the last."""
    path_rtol = PATH_RTOL if settings.path_rtol is None else settings.path_rtol
    return first_step_settings(replace(settings, path_rtol=path_rtol), largest_kpa, mu_kpa)
