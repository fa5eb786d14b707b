"""The mechanism in Exudyn, integration of concrete scenes, the independent reference DAE."""
