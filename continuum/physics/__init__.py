"""Pure physics shared by the continuum laws, references and surfaces (closed forms, no state)."""
