"""animsynth: reproduce and extend four data-driven character-animation methods."""

__version__ = "0.1.0"
