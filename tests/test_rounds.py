"""Model criticism, next rung: replacements and removals besides additions, rounds until the
residuals are noise, and effects that carry their own knowledge so a plug-in takes part on equal terms."""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from spacepol.criticism.changes import apply, changes, parse
from spacepol.io.measurements import Dataset, write_table
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid
from spacepol.physics.registry import registry
from cli_runner import run_cli


def _cli(*args):
    """The command line in this process (``cli_runner``)."""
    return run_cli(*args)


def _cli_process(*args):
    """The command line in a process of its own: for a plug-in loaded with --effect, which would stay registered."""
    return subprocess.run([sys.executable, "-m", "spacepol.cli", *map(str, args)], capture_output=True, text=True)


def _write(path, spec, truth, noise_dop=0.004, noise_brdf=0.02, seed=5):
    g = default_grid()
    pred = Model.from_string(spec).evaluate(truth, g)
    rng = np.random.default_rng(seed)
    write_table(path, {"theta_i": g.theta_i, "theta_r": g.theta_r, "dphi": g.dphi,
                       "dop": np.clip(pred.dop + noise_dop * rng.standard_normal(g.size), 0, 1), "dop_err": np.full(g.size, noise_dop),
                       "brdf": pred.brdf * (1 + noise_brdf * rng.standard_normal(g.size)), "brdf_err": noise_brdf * pred.brdf},
                {"model": spec, **{f"truth_{k}": v for k, v in truth.items()}})
    return path


def test_changes_are_additions_slot_replacements_and_removals():
    data = Dataset(np.array([30.0]), np.array([40.0]), np.array([180.0]))
    labels = {c.label for c in changes(Model.from_string("paper"), data)}
    assert {"replace shadowing by smith", "replace body by lambertian", "replace body by polarized_diffuse",
            "remove shadowing", "remove body", "add dop_bias", "add lambertian"} <= labels
    assert "add smith" not in labels  # smith excludes shadowing: only as a replacement
    assert not any("oxide_layer" in label for label in labels)  # it declares that it needs a wavelength
    assert "remove specular" not in labels  # not removable (everything else needs it)
    assert apply(Model.from_string("paper"), "replace shadowing by smith").name == "specular+smith+body"
    assert parse(Model.from_string("paper"), "remove body").model.name == "specular+shadowing"


PLUGIN = textwrap.dedent('''
    import numpy as np
    from spacepol.priors import Uniform
    from spacepol.physics.effect import Effect
    from spacepol.physics.parameter import Parameter

    class FlatShadow(Effect):
        """A user's shadowing term: a constant darkening (declares the shadowing slot)."""
        name = "flat_shadow"
        slot = "shadowing"
        removable = True
        requires = ("specular",)
        excludes = ("shadowing", "smith")
        parameters = (Parameter("g0", "", Uniform(0.5, 1.0), 0.9, "constant G"),)
        description = "Constant shadowing factor."
        def specular_factor(self, ctx):
            return ctx["g0"] + 0 * ctx.geometry.cos_ti

    class Analyser(Effect):
        """The same physics as extinction, declared its twin, with the measurement that separates them."""
        name = "leaky_analyser"
        twins = {"extinction": "a calibration with a known polarizer (the user's own note)"}
        neutral = {"e2": 1.0}
        parameters = (Parameter("e2", "", Uniform(0.5, 1.0), 0.95, "analyser efficiency", physical=(0.0, 1.0)),)
        description = "Leaky analyser: measured DOP = e2 x true DOP."
        def modify_stokes(self, ctx, total):
            return total.at[1:].multiply(ctx["e2"])
''')


@pytest.fixture
def plugins(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "_classes", dict(registry._classes))
    path = tmp_path / "mine.py"
    path.write_text(PLUGIN)
    registry.load_file(f"{path}:FlatShadow")
    registry.load_file(f"{path}:Analyser")
    return path


def test_a_plugin_declaring_a_slot_is_offered_as_a_replacement(plugins):
    data = Dataset(np.array([30.0]), np.array([40.0]), np.array([180.0]))
    labels = {c.label for c in changes(Model.from_string("paper"), data)}
    assert "replace shadowing by flat_shadow" in labels and "add flat_shadow" not in labels
    labels = {c.label for c in changes(Model.from_string("specular+smith+body"), data)}
    assert "replace smith by flat_shadow" in labels and "replace smith by shadowing" in labels


def test_a_plugin_declaring_twins_is_reported_as_tied(plugins, tmp_path):
    """Hidden extinction; the plug-in predicts exactly the same, declares itself its twin: both are refitted
    and reported tied, with the separating measurement the plug-in declares."""
    data = _write(tmp_path / "ext.csv", "paper+extinction", {"n": 1.5, "k": 0.0, "sigma": 0.2, "ks": 0.6, "rho_d": 0.2, "e": 0.75})
    out = tmp_path / "d.json"
    run = _cli_process("diagnose", data, "--effect", f"{plugins}:Analyser", "--model", "paper", "--candidates", "extinction",
               "leaky_analyser", "dop_bias", "--top", "1", "--json", out, "--out", tmp_path / "dg")
    assert run.returncode == 0, run.stderr
    report = json.loads(out.read_text())
    lead = report["ranking"][0]
    pair = {report["verdict"]} | set(lead.get("tied_with", []))
    assert pair == {"extinction", "leaky_analyser"}, (report["verdict"], lead.get("tied_with"))
    assert "known polarizer" in lead["explanation"]
    # negative control: the same data without the twin declared would not refit it (top 1 = only the leader)
    assert sum(r["delta_elpd"] is not None for r in report["ranking"]) == 2


def test_slot_alternatives_are_the_other_members_of_the_slots_the_path_changed():
    """What the end of a path is weighed against: the other members of each changed slot, filling an
    emptied slot, or emptying it; never an unrelated addition."""
    from spacepol.criticism.changes import slot_alternatives

    data = Dataset(np.array([30.0]), np.array([30.0]), np.array([180.0]))
    emptied = slot_alternatives(Model.from_string("specular+body"), data, {"shadowing"})
    assert {"add smith", "add shadowing"} <= set(emptied) and not any("body" in c or "dop_bias" in c for c in emptied)
    both = set(slot_alternatives(Model.from_string("specular+smith+lambertian"), data, {"shadowing", "body"}))
    assert {"replace smith by shadowing", "remove smith", "replace lambertian by body",
            "replace lambertian by polarized_diffuse", "remove lambertian"} <= both
    assert not any(c.startswith("add ") and c.split()[1] in ("dop_bias", "angle_offset", "extinction") for c in both)


@pytest.fixture(scope="module")
def swap_path(tmp_path_factory):
    """Data from specular+smith+lambertian (both of the paper's wrong parts replaced), fitted from paper with
    --rounds 3 over a small candidate list (the whole library is the slow test)."""
    tmp = tmp_path_factory.mktemp("swap")
    data = _write(tmp / "swap.csv", "specular+smith+lambertian", {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.6, "rho_l": 0.3})
    run = _cli("diagnose", data, "--model", "paper", "--rounds", "3", "--candidates", "smith", "lambertian", "dop_bias",
               "--top", "2", "--json", tmp / "d.json", "--out", tmp / "dg")
    assert run.returncode == 0, run.stderr
    return tmp, json.loads((tmp / "d.json").read_text()), run


@pytest.mark.slow  # test_tutorial climbs a path of rounds in the default suite
def test_rounds_replace_the_wrong_parts_until_the_residuals_are_noise(swap_path):
    tmp, report, run = swap_path
    rounds = report["rounds"]
    assert rounds[0]["model"] == "specular+shadowing+body" and rounds[0]["change"] is None
    assert all(set(r) >= {"model", "change", "delta_elpd", "delta_elpd_se", "fit"} for r in rounds)
    path = [r["change"] for r in rounds[1:]]
    assert "replace shadowing by smith" in path and "replace body by lambertian" in path, path
    assert report["final_model"] in ("specular+smith+lambertian", "specular+smith+lambertian+dop_bias")
    chi2 = [r["fit"]["chi2_red"] for r in rounds]
    assert chi2[0] > 3 and chi2[-1] < 1.5 and all(b < a for a, b in zip(chi2, chi2[1:]))  # falls at each round
    assert "Explained" in report["conclusion_rounds"]
    assert (tmp / "dg" / "path.png").stat().st_size > 0 and "round" in (tmp / "dg" / "report.html").read_text()


@pytest.mark.slow
def test_ladder_reads_the_path_to_replay(swap_path, tmp_path):
    """The replay's steps are the path's changes, in order; a path from another start model is refused
    before any fit (the full refit of the path is the slow test below)."""
    from spacepol.commands import replay_steps

    tmp, report, _ = swap_path
    steps = replay_steps(tmp / "d.json", Model.from_string("paper"))
    assert steps == [r["change"] for r in report["rounds"][1:]]
    model = Model.from_string("paper")
    for step in steps:
        model = parse(model, step).model
    assert model.name == report["final_model"]
    wrong = _cli("ladder", tmp / "swap.csv", "--model", "torrance-sparrow", "--replay", tmp / "d.json", "--out", tmp_path / "w")
    assert wrong.returncode == 2 and "starts from" in wrong.stderr and not (tmp_path / "w").exists()


@pytest.mark.slow
def test_ladder_replays_a_path(swap_path, tmp_path):
    tmp, report, _ = swap_path
    run = _cli("ladder", tmp / "swap.csv", "--model", "paper", "--replay", tmp / "d.json", "--json", tmp_path / "l.json",
               "--out", tmp_path / "l")
    assert run.returncode == 0, run.stderr
    rungs = json.loads((tmp_path / "l.json").read_text())["rungs"]
    assert [r["model"] for r in rungs] == [r["model"] for r in report["rounds"]]
    assert rungs[-1]["chi2_red"] < 1.5


def test_a_slot_alternative_better_than_the_final_model_is_reported():
    """The last pass searches each slot alternative globally; one that comes out significantly better than the model
    the rounds stopped at (refitted, or decided from the two optima) is named in the conclusion, the best first;
    equivalent and worse ones are not."""
    from spacepol.criticism.rounds import _better, _conclusion

    ranking = [
        {"change": "replace body by lambertian", "delta_elpd": 20.0, "delta_elpd_se": 5.0, "significant": True},
        {"change": "remove body", "delta_elpd": None, "delta_elpd_se": None, "significant": False,
         "plugin_delta": 300.0, "plugin_se": 20.0},
        {"change": "remove shadowing", "delta_elpd": None, "delta_elpd_se": None, "significant": False,
         "plugin_delta": -300.0, "plugin_se": 20.0},
        {"change": "replace shadowing by smith", "delta_elpd": 1.0, "delta_elpd_se": 3.0, "significant": False},
        {"change": "add ggx", "delta_elpd": 50.0, "delta_elpd_se": 5.0, "significant": True},  # not a slot alternative
    ]
    labels = [e["change"] for e in ranking[:4]]
    better = _better({"ranking": ranking}, labels)
    assert [e["change"] for e in better] == ["remove body", "replace body by lambertian"]
    assert better[0]["plug_in"] and not better[1]["plug_in"]
    final = {"model": "paper", "fit": {"chi2_red": 1.0}, "inferred_noise": {}, "structured": False,
             "residual_structure": [], "equivalent": [], "better": better}
    text = _conclusion([dict(final, better=[], equivalent=[]), dict(final, change="add lambertian")], [{}])
    assert "significantly better" in text and "remove body (+300.0 +- 20.0, from the two optima)" in text
    assert "significantly better" not in _conclusion([final | {"better": []}, dict(final, change="x", better=[])], [{}])
