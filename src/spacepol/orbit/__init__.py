"""A satellite's pass over a site: its TLE read and propagated with SGP4 (skyfield), the direction and range from the
site, the sun, whether the satellite is sunlit and the sky is in daylight, the phase angle, and each face's
incidence, reflection and azimuth angles in its own frame."""

from .attitude import Attitude, turned
from .faces import default_faces, faces_from_toml, read_target, target_faces, write_target
from .pass_geometry import Face, PassGeometry, pass_geometry
from .tle import TLE, read_tle

__all__ = ["Attitude", "read_target", "turned", "Face", "PassGeometry", "TLE", "default_faces", "faces_from_toml", "target_faces", "write_target", "pass_geometry", "read_tle"]
