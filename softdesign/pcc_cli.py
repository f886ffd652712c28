"""`softdesign pcc ...`: seed 003's piecewise-constant-curvature model (placeholder until issue 6 lands)."""

import typer

pcc_app = typer.Typer(no_args_is_help=True, help="Piecewise constant curvature (seed 003).")
