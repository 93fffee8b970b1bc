import pytest

from spacepol.errors import InputFileError
from spacepol.io.nk import RefractiveIndex
from spacepol.paths import bundled


def test_aluminium_at_1550nm_is_not_the_papers_visible_value():
    """ERRATA: near 1.55 um aluminium is n ~ 1.58, k ~ 15.7 (Rakic), not the paper's 1.24 + 6.6i."""
    N = RefractiveIndex(bundled("nk", "main_Al_nk_Rakic.yml"))(1.55)
    assert N.real == pytest.approx(1.58, abs=0.05) and N.imag == pytest.approx(15.7, abs=0.3)


def test_sapphire_sellmeier_and_kapton_tables():
    sapphire = RefractiveIndex(bundled("nk", "main_Al2O3_nk_Malitson.yml"))
    assert sapphire(0.5893).real == pytest.approx(1.768, abs=2e-3)  # ordinary ray at the sodium D line
    assert sapphire(0.5893).imag == 0
    kapton = RefractiveIndex(bundled("nk", "other_commercial_polymers_Kapton_nk_French.yml"))(0.633)
    assert kapton.real == pytest.approx(1.807, abs=1e-3) and 0 < kapton.imag < 1e-3


def test_outside_the_table_is_an_error():
    with pytest.raises(InputFileError, match="outside the tabulated range"):
        RefractiveIndex(bundled("nk", "main_Al2O3_nk_Malitson.yml"))(10.0)
