"""The elastic half-space under the roller (FFT influence, limiting-pressure checks)."""
