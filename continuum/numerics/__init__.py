"""The compiled contact phase and its integrator tableau (numba kernels, DOP853 coefficients)."""
