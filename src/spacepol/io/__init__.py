"""Measurement files: the spacepol CSV layout and NIST's full Mueller-matrix BRDF layout."""

from .measurements import Dataset, read_measurements, write_table

__all__ = ["Dataset", "read_measurements", "write_table"]
