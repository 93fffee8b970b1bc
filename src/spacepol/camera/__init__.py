"""Division-of-focal-plane (micro-polarizer) cameras: the analyser layout of the 2x2 superpixel, demosaicking, and the
linear Stokes parameters, DoLP and AoP of each pixel."""

from .mosaic import IMX250MZR, Layout, StokesMaps, demosaic, linear_stokes, read_raw_frame, stokes_maps, superpixels

__all__ = ["IMX250MZR", "Layout", "StokesMaps", "demosaic", "linear_stokes", "read_raw_frame", "stokes_maps", "superpixels"]
