"""The actuation chambers and their feed lines: where they run, the body with them carved out, their walls, and a
hollow body's chamber surface."""
