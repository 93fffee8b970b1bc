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


def test_a_refractive_index_table_is_a_prior(tmp_path):
    """`nk_table` in a prior file: a truncated normal at the table's n or k at the parameter's wavelength
    (n@0.633 says it; a plain n needs wavelength_um); bad entries are one-line errors naming file and key."""
    from spacepol.errors import ParameterError
    from spacepol.infer.prior_set import read_prior_file

    path = tmp_path / "priors.toml"
    path.write_text('["n@0.633"]\nnk_table = "other_commercial_polymers_Kapton_nk_French.yml"\n'
                    '[k]\nnk_table = "main_Al_nk_Rakic.yml"\nwavelength_um = 1.55\nrelative_sigma = 0.1\n')
    priors = read_prior_file(path)
    kapton, aluminium = priors["n@0.633"], priors["k"]
    assert kapton.mu == pytest.approx(1.807, abs=1e-3) and kapton.sigma == pytest.approx(0.05 * kapton.mu)
    assert aluminium.mu == pytest.approx(15.7, abs=0.3) and aluminium.sigma == pytest.approx(0.1 * aluminium.mu)
    for text, words in [('[n]\nnk_table = "main_Al_nk_Rakic.yml"\n', "needs wavelength_um"),
                        ('[sigma]\nnk_table = "main_Al_nk_Rakic.yml"\nwavelength_um = 0.6\n', "not sigma"),
                        ('["n@0.633"]\nnk_table = "nothing.yml"\n', "nothing.yml"),
                        ('["n@9.9"]\nnk_table = "other_commercial_polymers_Kapton_nk_French.yml"\n', "outside the tabulated range")]:
        path.write_text(text)
        with pytest.raises(ParameterError, match=words):
            read_prior_file(path)
