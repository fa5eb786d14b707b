"""Fitted rules: the rigid-or-flexible laws of the coupler (``kfit``) and the crank (``crank``)
through one pipeline, and the FFRF settings rule calibrated on work-precision grids
(``calibrate``)."""
