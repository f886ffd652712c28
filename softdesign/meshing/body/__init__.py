"""The body S(q): its sections swept along the centerline, the pose with one q per link, the morph on one
tessellation, the hollow body's wall and the skin's stretch."""
