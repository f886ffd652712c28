"""The casting mould of the body at q = 0: the two halves, the cores of a hollow or actuated body, and their
checks."""
