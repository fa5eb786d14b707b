"""Work-precision: what accuracy costs. The shared core (settings, runs and their errors,
converged references, the Pareto front), the tradeoff study, the defaults and rule checks, the
benchmark and the error-estimate check."""
