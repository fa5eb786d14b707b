"""What a scene resolves to: the "auto" solver settings and which keys a run uses."""
