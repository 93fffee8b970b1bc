"""The observing scenario, from TOML: site and time, sky model, target geometry, instrument.

Keys carry their unit in their name (``integration_time_s``); a value may be a number in that
unit or a string with an explicit unit that astropy converts ("25 ms"). Unknown keys, wrong
units and impossible values (negative areas, transmittances above 1) are errors naming the key.
The defaults are the paper's (section 4 and Table 2); ``default_scenario()`` returns them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SpacepolError
from ..io.toml_file import read_toml

# key: (astropy unit or "" for dimensionless, default, check) ; check in {"positive", "fraction", "any", "nonnegative"}
SITE = {"lat_deg": ("deg", 43 + 8 / 60, "any"), "lon_deg": ("deg", 125 + 32 / 60, "any"),
        "time": (None, "2020-12-16T11:42:00+08:00", "text")}
SKY = {"model": (None, "rayleigh", "text"), "p_max_low": ("", 0.7, "fraction"), "p_max_high": ("", 0.85, "fraction"),
       "delta_deg": ("deg", 20.0, "nonnegative")}
TARGET = {"theta_i_deg": ("deg", 30.0, "any"), "dphi_deg": ("deg", 180.0, "any"),
          "theta_r_low_deg": ("deg", 0.0, "any"), "theta_r_high_deg": ("deg", 80.0, "any"),
          # where the material's n, k are taken from a run over several wavelengths; None: the band's centre
          "wavelength_um": ("um", None, "positive")}
INSTRUMENT = {  # Table 2 and the text around eqs 35-39
    "spot_pixels": ("", 4.0, "positive"),  # k
    "pupil_area_m2": ("m2", 2.544, "positive"),  # A_0
    "system_transmittance": ("", 0.9, "fraction"),  # tau_0
    "atmospheric_transmittance": ("", 0.7, "fraction"),  # tau_s
    "polarizer_transmittance": ("", 0.7, "fraction"),  # tau_p
    "quantum_efficiency": ("", 0.65, "fraction"),  # Q_B
    "integration_time_s": ("s", 0.025, "positive"),  # t_s
    "obscuration_ratio": ("", 0.2, "fraction"),  # epsilon
    "target_filter_transmittance": ("", 0.13, "fraction"),  # f_s
    "background_filter_transmittance": ("", 0.021, "fraction"),  # f_B
    "background_integration_time_s": ("s", 0.025, "positive"),  # t_B
    "background_magnitude": ("", 22.0, "any"),  # M_B (paper: deep-sky equivalent; a night value)
    "pixel_ifov_arcsec": ("arcsec", 0.047, "positive"),  # A_p = d_pix / f'
    "dark_current_e_per_s": ("", 0.183, "nonnegative"),  # N_D
    "read_noise_e": ("", 60.0, "nonnegative"),  # N_R
    "band_low_um": ("um", 1.5, "positive"), "band_high_um": ("um", 1.8, "positive"),
    "star_temperature_K": ("K", 5900.0, "positive"),  # T_0
    "bolometric_correction": ("", 0.08, "any"),  # bc
    "limit_flux_photons_m2_s": ("", 8.472e5, "positive"),  # the paper's Phi_s at the detection limit
    "snr_required": ("", 6.0, "positive"),
    "sky_magnitude": ("", 5.40, "any"),  # M_sky implied by Table 3's raw contrasts (not in the paper)
}
SECTIONS = {"site": SITE, "sky": SKY, "target": TARGET, "instrument": INSTRUMENT}
CASE_KEYS = {"name": (None, None, "text"), "zenith_deg": ("deg", None, "any"), "azimuth_deg": ("deg", None, "any"),
             "sky_dop": ("", None, "fraction"), "theta_r_deg": ("deg", None, "any")}
PAPER_CASES = [  # Table 3: "A" is the zenith angle, "E" the azimuth (row 2's azimuth: 101 deg 28' in the table)
    {"name": "A = 10 deg, E = 101 deg 28'", "zenith_deg": 10.0, "azimuth_deg": 101 + 28 / 60},
    {"name": "A = 60 deg, E = 101 deg 28'", "zenith_deg": 60.0, "azimuth_deg": 101 + 28 / 60},
]


@dataclass
class Scenario:
    """A detection scenario, checked: ``site`` (latitude, longitude, time), ``sky`` (model, P_max range),
    ``target`` (geometry, wavelength), ``instrument`` (Table 2's radiometry), the ``cases`` (directions on the
    sky) and ``source`` (the file it came from, or the paper's default)."""

    site: dict
    sky: dict
    target: dict
    instrument: dict
    cases: list[dict] = field(default_factory=list)
    source: str = "default (the paper's section 4 and Table 2)"


def _value(where: str, key: str, raw, spec):
    unit, _, check = spec
    if unit is None:
        if not isinstance(raw, str):
            raise SpacepolError(f"{where}: '{key}' must be a string")
        return raw
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise SpacepolError(f"{where}: '{key}' must be a number or a string with a unit")
    if isinstance(raw, str):
        import astropy.units as u

        try:
            quantity = u.Quantity(raw)
        except (TypeError, ValueError):
            raise SpacepolError(f"{where}: '{key}' = '{raw}' is not a number with a unit") from None
        target = u.Unit(unit) if unit else u.dimensionless_unscaled
        try:
            value = float(quantity.to_value(target))
        except u.UnitConversionError:
            shown = unit or "dimensionless"
            raise SpacepolError(f"{where}: '{key}' = '{raw}': unit {quantity.unit} cannot be converted to {shown}") from None
    else:
        value = float(raw)
    if not math.isfinite(value):
        raise SpacepolError(f"{where}: '{key}' = {raw!r} must be a finite number")
    if check == "positive" and not value > 0:
        raise SpacepolError(f"{where}: '{key}' = {value:g} must be > 0")
    if check == "nonnegative" and value < 0:
        raise SpacepolError(f"{where}: '{key}' = {value:g} must be >= 0")
    if check == "fraction" and not 0 <= value <= 1:
        raise SpacepolError(f"{where}: '{key}' = {value:g} must lie in [0, 1]")
    return value


def _section(where: str, table: dict, specs: dict, defaults: bool = True) -> dict:
    unknown = sorted(set(table) - set(specs))
    if unknown:
        raise SpacepolError(f"{where}: unknown key(s) {', '.join(unknown)} (known: {', '.join(specs)})")
    out = {k: spec[1] for k, spec in specs.items()} if defaults else {}
    for key, raw in table.items():
        out[key] = _value(where, key, raw, specs[key])
    return out


def default_scenario() -> Scenario:
    """The paper's scenario: its section 4 site and time, Table 2's instrument and Table 3's cases."""
    return Scenario(*(_section(name, {}, specs) for name, specs in SECTIONS.items()), cases=[dict(c) for c in PAPER_CASES])


def read_scenario(path) -> Scenario:
    """The scenario of a TOML file (sections as ``default_scenario``'s; any key left out keeps its default)."""
    path = Path(path)
    return scenario_from_dict(read_toml(path, "scenario"), str(path))


def scenario_from_dict(data: dict, path: str = "scenario") -> Scenario:
    """The scenario of a dict laid out as the TOML file (``{"target": {"wavelength_um": 0.8}, "cases": [...]}``),
    checked as a file is; ``path`` names it in error messages."""
    unknown = sorted(set(data) - set(SECTIONS) - {"cases"})
    if unknown:
        raise SpacepolError(f"{path}: unknown section(s) {', '.join(unknown)} (known: {', '.join(SECTIONS)}, cases)")
    parts = {}
    for name, specs in SECTIONS.items():
        table = data.get(name, {})
        if not isinstance(table, dict):
            raise SpacepolError(f"{path}: [{name}] must be a table")
        parts[name] = _section(f"{path} [{name}]", table, specs)
    cases = []
    for i, case in enumerate(data.get("cases", PAPER_CASES)):
        where = f"{path} [[cases]] #{i + 1}"
        if not isinstance(case, dict):
            raise SpacepolError(f"{where}: each case must be a table")
        c = _section(where, case, CASE_KEYS, defaults=False)
        missing = [k for k in ("zenith_deg", "azimuth_deg") if k not in c]
        if missing:
            raise SpacepolError(f"{where}: missing {', '.join(missing)}")
        if not 0 <= c["zenith_deg"] <= 90:
            raise SpacepolError(f"{where}: zenith_deg = {c['zenith_deg']:g} must lie in [0, 90] (above the horizon)")
        c.setdefault("name", f"zenith {c['zenith_deg']:g} deg, azimuth {c['azimuth_deg']:g} deg")
        cases.append(c)
    s = Scenario(**parts, cases=cases, source=str(path))
    if s.instrument["band_low_um"] >= s.instrument["band_high_um"]:
        raise SpacepolError(f"{path} [instrument]: band_low_um must be below band_high_um")
    if s.sky["p_max_low"] > s.sky["p_max_high"]:
        raise SpacepolError(f"{path} [sky]: p_max_low must not exceed p_max_high")
    if s.sky["model"] not in ("rayleigh", "berry-dennis-lee"):
        raise SpacepolError(f"{path} [sky]: model '{s.sky['model']}' unknown (rayleigh, berry-dennis-lee)")
    check_scenario(s, str(path))
    return s


def check_scenario(s: Scenario, where: str) -> None:
    """Checks that need several keys at once, or a computation: the site, the time, a band whose flux
    is finite and positive (a band far from the star's spectrum underflows to zero photons)."""
    from ..skylight.sun import parse_time
    from .radiometry import magnitude

    if not -90 <= s.site["lat_deg"] <= 90:
        raise SpacepolError(f"{where} [site]: 'lat_deg' = {s.site['lat_deg']:g} must lie in [-90, 90]")
    if not -180 <= s.site["lon_deg"] <= 360:
        raise SpacepolError(f"{where} [site]: 'lon_deg' = {s.site['lon_deg']:g} must lie in [-180, 360]")
    try:
        parse_time(s.site["time"])
    except SpacepolError as exc:
        raise SpacepolError(f"{where} [site]: 'time': {str(exc).split(': ', 1)[-1]}") from None
    with np.errstate(all="ignore"):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = float(magnitude(s.instrument["limit_flux_photons_m2_s"], s.instrument))
    if not math.isfinite(m):
        raise SpacepolError(f"{where} [instrument]: the band {s.instrument['band_low_um']:g}-{s.instrument['band_high_um']:g} um "
                            f"holds no finite photon flux of a {s.instrument['star_temperature_K']:g} K star "
                            f"(eq 39 gives magnitude {m}); choose a band where the star emits")
