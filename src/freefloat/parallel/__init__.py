"""Parallel mechanisms by Orsino's subsystem coupling (thesis proposal secs 5.3-5.4)."""
