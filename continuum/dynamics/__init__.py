"""The roller's equation of motion: the event-driven driver, one impact, escape velocities, ensembles of impacts."""
