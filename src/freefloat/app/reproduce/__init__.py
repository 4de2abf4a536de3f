"""Reproductions of the documents' experiments against the exact reference."""
