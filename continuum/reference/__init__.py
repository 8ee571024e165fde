"""Closed-form reference solutions (Hertz, JKR) used to validate the numerical laws."""
