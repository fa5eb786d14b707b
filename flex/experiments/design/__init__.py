"""The design study and ``flex design``: the design point's cases, the summary of the charts, the
mechanism checks, the report and figures, and a designer's question about one scene."""
