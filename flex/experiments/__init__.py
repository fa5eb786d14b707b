"""What the studies compute, shelved by what it is: ``thesis`` (one back-end per thesis study),
``fitting`` (the rigid-or-flexible laws, the FFRF settings rule), ``workprecision`` (what
accuracy costs), ``design`` (design charts, ``flex design``) and ``models`` (flex's models
checked beyond the thesis). docs/layout.md lists every module.
"""
