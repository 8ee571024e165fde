"""Rough-surface contact: Greenwood-Williamson summits with JKR adhesion and Fuller-Tabor hysteresis.

``gw``            the load-separation law per unit nominal area (``GWJKRSurface``), its history threshold,
                  energy and dissipation, evaluated from fast tables with measured error.
``summits``       summit statistics and the closed forms (GW integral, JKR in s = sqrt(a/a0)).
``gw_layout``     the tables' layout, size estimate (``table_size``) and Hermite interpolants.
``gw_reference``  the defining integrals by adaptive quadrature, and ``table_error`` against them.
``gw_branches``   the same model with the JKR branch laws of the Maugis-Dugdale and DMT regimes.
``datum``  the tallest summit expected in the roller's footprint (truncation of the Gaussian).

Equations, decomposition, table error and cost: ``docs/rough-gw.md``.
"""
