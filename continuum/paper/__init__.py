"""`nanoimpact paper`: every case of the founding paper for every parameter set, with its figures and claims."""
