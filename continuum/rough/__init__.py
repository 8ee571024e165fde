"""Rough-surface contact: Greenwood-Williamson summits with JKR adhesion and Fuller-Tabor hysteresis.

``gw``            the load-separation law per unit nominal area (``GWJKRSurface``), its history threshold,
                  energy and dissipation, evaluated from fast tables with measured error.
``summits``       summit statistics and the closed forms (GW integral, JKR in s = sqrt(a/a0)).
``gw_layout``     the tables' layout, size estimate (``table_size``) and Hermite interpolants.
``gw_reference``  the defining integrals by adaptive quadrature, and ``table_error`` against them.
``gw_branches``   the same model with the JKR branch laws of the Maugis-Dugdale and DMT regimes.
``datum``  the tallest summit expected in the roller's footprint (truncation of the Gaussian).
``topography``    height maps (read or synthesised by SurfaceTopography, SI, detrended) and their summits:
                  ``load_height_map``, ``identify_summits`` (direct route), ``summit_statistics`` (both routes).
``summit_stats``  the spectral (Nayak/McCool) and direct summaries of a filtered map.
``surface_map``   a scene's map keys -> the statistics that fill sigma, summit_density, summit_radius.

Equations, decomposition, table error and cost: ``docs/rough-gw.md``.
"""
