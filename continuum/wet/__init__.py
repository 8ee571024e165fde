"""Capillary physics: Kelvin radius, meniscus bridges and their condensation clock."""
