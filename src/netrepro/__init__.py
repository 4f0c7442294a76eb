"""netrepro: reproducing five papers on networked estimation and control.

The package holds all the mathematics of the pipeline. Shared engines live in
:mod:`netrepro.engines` (loss channels, batched Riccati recursions, Monte Carlo,
LMI helpers); each paper has one module in :mod:`netrepro.papers`. The
Snakemake rules call into the package through :mod:`netrepro.pipeline.runner`.
"""

__all__ = ["__version__"]

__version__ = "0.1.0"
