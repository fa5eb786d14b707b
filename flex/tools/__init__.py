"""Reading result files: inspect, compare, plot, report."""
