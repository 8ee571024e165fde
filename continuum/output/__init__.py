"""What a run gives back: the typed result, its provenance, notices (warnings) and figures."""
