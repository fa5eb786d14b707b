"""flex: flexible multibody study workspace (Exudyn + NGsolve + HDF5).

Library modules, one per concept:

- :mod:`flex.scene` -- scenes (TOML parameter sets), validation, overrides
- :mod:`flex.mechanism` -- slider-crank assembly in Exudyn (rigid or FFRF coupler)
- :mod:`flex.solver` -- time integration, output collection, divergence detection
- :mod:`flex.reference` -- independent 9-coordinate Lagrange-multiplier DAE (scipy)
- :mod:`flex.kinematics` -- closed-form slider-crank kinematics
- :mod:`flex.plate`, :mod:`flex.modal`, :mod:`flex.reduction` -- NGsolve meshes, modal
  analysis, Craig-Bampton reduction and FFRF bodies
- :mod:`flex.results` -- HDF5 result files with units and provenance
"""

__version__ = "0.1.0"
