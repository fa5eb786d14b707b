"""What a scene resolves to: the calibration (fitted laws, FFRF rule, solver defaults), the
"auto" solver settings and which keys a run uses."""
