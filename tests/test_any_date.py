"""The sun and sky for any date, offline: today and five years ahead, where astropy's bundled
Earth-orientation predictions have run out.  Checked against the Astronomical Almanac's
low-precision solar coordinates (good to ~0.01 deg for 1950-2050), written here independently of
astropy; the contrast command runs for both dates too."""

import json
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

from spacepol.skylight.sun import sun_position
from test_contrast import _run_dir
from cli_runner import run_cli

TODAY = datetime.now(timezone.utc).replace(hour=4, minute=0, second=0, microsecond=0)
DATES = {"today": TODAY, "in five years": TODAY.replace(year=TODAY.year + 5) if not (TODAY.month == 2 and TODAY.day == 29)
         else TODAY + timedelta(days=5 * 365)}
SITE = (43 + 8 / 60, 125 + 32 / 60)  # the paper's site


def almanac_sun(lat_deg, lon_deg, when: datetime):
    """Zenith and azimuth (east of north) from the Almanac's low-precision formulae (section C5)."""
    jd = when.timestamp() / 86400.0 + 2440587.5
    n = jd - 2451545.0
    mean_lon = np.radians((280.460 + 0.9856474 * n) % 360)
    g = np.radians((357.528 + 0.9856003 * n) % 360)
    ecl_lon = mean_lon + np.radians(1.915) * np.sin(g) + np.radians(0.020) * np.sin(2 * g)
    eps = np.radians(23.439 - 0.0000004 * n)
    ra = np.arctan2(np.cos(eps) * np.sin(ecl_lon), np.cos(ecl_lon))
    dec = np.arcsin(np.sin(eps) * np.sin(ecl_lon))
    gmst = np.radians((280.46061837 + 360.98564736629 * n) % 360)
    ha = gmst + np.radians(lon_deg) - ra
    lat = np.radians(lat_deg)
    alt = np.arcsin(np.sin(lat) * np.sin(dec) + np.cos(lat) * np.cos(dec) * np.cos(ha))
    az = np.arctan2(-np.cos(dec) * np.sin(ha), np.sin(dec) * np.cos(lat) - np.cos(dec) * np.cos(ha) * np.sin(lat))
    return 90.0 - np.degrees(alt), np.degrees(az) % 360.0


@pytest.mark.parametrize("label", list(DATES))
def test_sun_for_today_and_five_years_ahead_matches_the_almanac(label):
    when = DATES[label]
    sun = sun_position(*SITE, when)
    zen, az = almanac_sun(*SITE, when)
    # the almanac's formulae ignore aberration details and nutation (~0.01 deg) and use the geocentre
    # (parallax 0.0024 deg): 0.05 deg is the tolerance the project tests the sun to
    assert abs(sun.zenith_deg - zen) < 0.05 and abs((sun.azimuth_deg - az + 180) % 360 - 180) < 0.05 / np.sin(np.radians(zen))


def test_the_almanac_check_fails_for_an_hour_off():
    """Negative control: one hour of clock error moves the sun by ~10 deg of azimuth; the check must see it."""
    sun = sun_position(*SITE, DATES["today"])
    zen, az = almanac_sun(*SITE, DATES["today"] + timedelta(hours=1))
    assert abs(sun.zenith_deg - zen) > 0.05 or abs((sun.azimuth_deg - az + 180) % 360 - 180) > 0.05


@pytest.mark.slow  # two CLI processes per date; the sun for both dates is checked in-process above
@pytest.mark.parametrize("label", list(DATES))
def test_sky_and_contrast_commands_run_for_today_and_five_years_ahead(tmp_path, label):
    iso = DATES[label].isoformat()
    sky = run_cli("sky", "--lat", str(SITE[0]), "--lon", str(SITE[1]),
                  "--time", iso, "--direction", "60,101.5", "--out", str(tmp_path / "sky"))
    assert sky.returncode == 0, sky.stderr
    assert "Traceback" not in sky.stderr and len([s for s in sky.stderr.splitlines() if s.strip()]) <= 1  # one note at most
    report = json.loads((tmp_path / "sky" / "sky.json").read_text())
    zen, _ = almanac_sun(*SITE, DATES[label])
    assert abs(report["sun"]["zenith_deg"] - zen) < 0.05

    run = _run_dir(tmp_path)
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'[site]\ntime = "{iso}"\n')
    contrast = run_cli("contrast", str(run), "--scenario", str(scenario),
                       "--draws", "500", "--out", str(tmp_path / "c"))
    assert contrast.returncode == 0, contrast.stderr
    rows = json.loads((tmp_path / "c" / "contrast.json").read_text())["rows"]
    assert all(np.isfinite(r["sky_dop"]["median"]) for r in rows)
