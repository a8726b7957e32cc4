"""File formats: ASF/AMC, BVH, OBJ sequences, CK+ landmarks."""

from .amc import read_amc, write_amc
from .asf import read_asf, write_asf
from ..errors import MotionFormatError

__all__ = ["MotionFormatError", "read_amc", "read_asf", "write_amc", "write_asf"]
