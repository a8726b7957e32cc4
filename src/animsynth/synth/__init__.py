"""Synthetic data generators that write the real file formats."""
