"""Measured-data discrepancy workflow for Granary (tools/discrepancy).

Modules: inputs (data, model and candidate files), runner (granary runs,
cached and in parallel), fitting (bounded robust least squares), stats
(chi-square, held-out errors, bootstrap, information criteria), report
(Markdown, JSON, PNG) and workflow (the steps in order).
"""
