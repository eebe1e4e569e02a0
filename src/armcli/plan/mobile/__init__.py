"""Mobile manipulation: where the base stands, how it drives there, and the arm from there."""
