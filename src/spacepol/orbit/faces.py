"""A target's faces from a TOML file (``[[faces]]`` tables: name, area_m2, orientation, normal, and optionally a
``material`` table of fixed parameters, ``{model = "specular+smith", n = 1.37, k = 7.6, sigma = 0.1, ks = 0.9}``,
where the face is not made of the observed run's material), and the default target: a 1 m cube bus in the orbit
frame with a 4 m^2 sun-tracking panel."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import ParameterError
from .attitude import Attitude, attitude_from_table, turned
from .pass_geometry import Face

FACE_KEYS = {"name", "area_m2", "orientation", "normal", "material"}


def default_faces() -> list[Face]:
    """A 1 m cube (six 1 m^2 faces, nadir-pointing: +-x along and against the velocity, +-y across, +-z to and away
    from the Earth) and a 4 m^2 panel tracking the sun."""
    axes = {"ram": (1, 0, 0), "wake": (-1, 0, 0), "starboard": (0, 1, 0), "port": (0, -1, 0), "nadir": (0, 0, 1),
            "zenith": (0, 0, -1)}
    return [Face(name, 1.0, "nadir", normal) for name, normal in axes.items()] + [Face("solar_panel", 4.0, "sun")]


def _read(path: Path) -> dict:
    if not path.is_file():
        raise ParameterError(f"--target {path}: file not found")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ParameterError(f"--target {path}: not valid TOML ({exc})") from None


def read_target(path) -> tuple[list[Face], Attitude | None]:
    """(the ``[[faces]]`` of a target TOML file, its top-level ``attitude = {yaw_deg, pitch_deg, roll_deg}`` offsets
    or None where it has none), the file read once; a bad table is one line naming the file."""
    path = Path(path)
    content = _read(path)
    table = content.get("attitude")
    return _faces(path, content.get("faces")), None if table is None else attitude_from_table(table, f"--target {path}")


def faces_from_toml(path) -> list[Face]:
    """The ``[[faces]]`` of a target TOML file (``read_target``'s faces)."""
    return read_target(path)[0]


def _faces(path: Path, tables) -> list[Face]:
    """The faces of a file's ``[[faces]]`` tables; an unknown key, a missing area or a bad value is one line naming
    the face."""
    if not isinstance(tables, list) or not tables:
        raise ParameterError(f"--target {path}: no [[faces]] tables (each with name, area_m2, orientation, normal)")
    faces = []
    for k, table in enumerate(tables, start=1):
        unknown = sorted(set(table) - FACE_KEYS)
        if unknown:
            raise ParameterError(f"--target {path}: face {k} has no key {', '.join(unknown)} (known: {', '.join(sorted(FACE_KEYS))})")
        if "area_m2" not in table:
            raise ParameterError(f"--target {path}: face {k} needs area_m2")
        material = table.get("material")
        if material is not None and not (isinstance(material, dict) and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for key, v in material.items() if key != "model")):
            raise ParameterError(f"--target {path}: face {k}: material must be a table of model = \"...\" and numbers")
        try:
            faces.append(Face(str(table.get("name", f"face{k}")), float(table["area_m2"]), str(table.get("orientation", "nadir")),
                              tuple(float(v) for v in table.get("normal", (0.0, 0.0, 1.0))), material))
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"--target {path}: face {k}: {exc}") from None
    names = [f.name for f in faces]
    if len(set(names)) != len(names):
        raise ParameterError(f"--target {path}: two faces share a name ({', '.join(sorted({n for n in names if names.count(n) > 1}))})")
    return faces


def target_faces(path) -> list[Face]:
    """The faces of a target TOML file as they fly: turned by the file's top-level ``attitude`` offsets where it has
    them (``attitude.turned``), as written where it has none."""
    faces, attitude = read_target(path)
    return faces if attitude is None else turned(faces, attitude)


def write_target(path, faces: list[Face], attitude: Attitude | None = None) -> Path:
    """A target TOML file that ``read_target`` reads back as ``faces`` and ``attitude`` (None: no attitude table)."""

    def value(v):
        return f'"{v}"' if isinstance(v, str) else repr(float(v))

    lines = [] if attitude is None else ["attitude = {" + ", ".join(f"{k} = {value(v)}" for k, v in attitude.to_json().items()) + "}"]
    for face in faces:
        lines += ["[[faces]]", f'name = "{face.name}"', f"area_m2 = {value(face.area_m2)}", f'orientation = "{face.orientation}"',
                  f"normal = [{', '.join(value(v) for v in face.normal)}]"]
        if face.material is not None:
            lines.append("material = {" + ", ".join(f"{k} = {value(v)}" for k, v in face.material.items()) + "}")
    path = Path(path)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
