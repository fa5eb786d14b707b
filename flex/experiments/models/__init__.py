"""flex's models checked beyond the thesis: the model ladder of a plate coupler, validation
against a published benchmark, numerical stability at the extremes, and the spring's own mass."""
