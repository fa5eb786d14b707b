"""One back-end per thesis study, named after its study: what it stores, reports and draws."""
