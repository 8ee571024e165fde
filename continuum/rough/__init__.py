"""Rough-surface contact: Greenwood-Williamson summits with JKR adhesion and Fuller-Tabor hysteresis.

``gw``     the load-separation law per unit nominal area (``GWJKRSurface``), its history threshold,
           energy and dissipation, fast tables with measured error, and quadrature references.
``datum``  the tallest summit expected in the roller's footprint (truncation of the Gaussian).

Equations, decomposition, table error and cost: ``docs/_fragments/rough_gw.md``.
"""
