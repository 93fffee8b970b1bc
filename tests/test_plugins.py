"""A user's own effect works by name: loaded from a file or through the entry-point group."""

import subprocess
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from spacepol.errors import ParameterError, SpacepolError
from spacepol.physics import Geometry, Model
from spacepol.physics.registry import Registry

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "user_effects.py"


def test_file_plugin_composes_by_name():
    reg = Registry()
    for cls in __import__("spacepol.physics.registry", fromlist=["x"]).BUILTIN_EFFECTS:
        reg.register(cls)
    surge = reg.load_file(f"{EXAMPLE}:OppositionSurge")
    assert reg.get("opposition_surge") is surge
    model = Model([reg.get(n) for n in ["specular", "shadowing", "body"]] + [surge])
    assert [p.name for p in model.free_parameters][-2:] == ["b0", "h_deg"]
    g = Geometry(np.array([30.0, 30.0]), np.array([30.0, 60.0]), np.array([0.0, 0.0]))  # retro, off-retro
    base = Model.from_string("paper").evaluate({}, g)
    with_surge = model.evaluate({"b0": 0.2, "h_deg": 5.0}, g)
    assert with_surge.brdf[0] - base.brdf[0] == pytest.approx(0.2)
    assert with_surge.brdf[1] - base.brdf[1] == pytest.approx(0.2 * np.exp(-30 / 5.0))
    assert np.all(with_surge.dop < base.dop + 1e-15)  # unpolarized light only dilutes


def test_decorated_function_plugin():
    reg = Registry()
    scale = reg.load_file(f"{EXAMPLE}:DopScaleError")
    assert scale.name == "dop_scale_error"
    g = Geometry(np.array([40.0]), np.array([40.0]), np.array([180.0]))
    base = Model.from_string("paper").evaluate({}, g).dop
    scaled = (Model.from_string("paper") + scale).evaluate({"gain": 0.9}, g).dop
    assert scaled[0] == pytest.approx(0.9 * base[0])


def test_entry_point_plugin(tmp_path, monkeypatch):
    pkg = tmp_path / "my_optics_effects.py"
    pkg.write_text(EXAMPLE.read_text())
    dist = tmp_path / "my_optics-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-optics\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[spacepol.effects]\nopposition_surge = my_optics_effects:OppositionSurge\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    reg = Registry()
    assert "opposition_surge" in reg.names()
    assert reg.get("opposition_surge").__name__ == "OppositionSurge"


def test_parameter_collision_raises():
    from spacepol.physics.effects import Effect, Parameter
    from spacepol.priors import Uniform

    class Clash(Effect):
        name = "clash"
        parameters = (Parameter("sigma", "", Uniform(0, 1), 0.1, "duplicate name"),)

    with pytest.raises(ParameterError, match="collides"):
        Model.from_string("specular") + Clash()


def test_composition_rules():
    with pytest.raises(SpacepolError, match="replaces"):
        Model.from_string("specular+shadowing+smith")
    with pytest.raises(SpacepolError, match="needs 'specular'"):
        Model.from_string("body+shadowing")
    with pytest.raises(SpacepolError, match="unknown effect 'glitter'"):
        Model.from_string("paper+glitter")
    assert (Model.from_string("specular") + "body").name == "specular+body"
    assert "sigma" not in [p.name for p in Model.from_string("specular+anisotropy").parameters]


def test_cli_effect_option_makes_the_name_usable(tmp_path):
    out = tmp_path / "synth.csv"
    cmd = [sys.executable, "-m", "spacepol.cli", "--effect", f"{EXAMPLE}:OppositionSurge", "synth",
           "--model", "paper+opposition_surge", "--set", "b0=0.3", "--out", str(out)]
    run = subprocess.run(cmd, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    listing = subprocess.run([sys.executable, "-m", "spacepol.cli", "--effect", f"{EXAMPLE}:OppositionSurge", "effects"],
                             capture_output=True, text=True)
    assert "opposition_surge" in listing.stdout and "b0 [sr^-1]" in listing.stdout


def test_dop_alone_names_a_plugin_jax_cannot_trace():
    """``Model.dop`` (its own compiled program) turns a plug-in written for numpy into the same one-line error
    as ``evaluate``; a traceable plug-in gives evaluate's DOP."""
    from spacepol.physics.effect import Effect

    class NumpyGlow(Effect):
        name = "numpy_glow"

        def lobe(self, ctx):
            return ctx.depolarized(np.exp(-np.asarray(ctx.geometry.cos_tr * ctx["ks"])))

    g = Geometry(np.array([30.0, 45.0]), np.array([20.0, 60.0]), np.array([180.0, 180.0]))
    sets = {"ks": np.array([0.3, 0.6])}
    with pytest.raises(SpacepolError, match="numpy_glow"):
        Model([*Model.from_string("paper").effects, NumpyGlow()]).dop(sets, g)
    model = Model.from_string("paper")
    np.testing.assert_allclose(model.dop(sets, g), model.evaluate(sets, g).dop, rtol=1e-14, atol=1e-15)


def test_dop_program_divides_before_a_plugin_hook_that_sees_the_lobe():
    """``Model.dop`` keeps the specular lobe over its Fresnel denominator (nothing in the DOP depends on a common
    positive factor); a plug-in's modify_specular or modify_stokes must still see the true lobe, and a plug-in's
    polarized array lobe is added at the true scale: the DOP equals evaluate's with each such plug-in."""
    from spacepol.physics.effect import Effect

    class HalfS1(Effect):  # not scale-free on its own: adds a fixed amount to S0 of the specular lobe
        name = "half_s1"

        def modify_specular(self, ctx, lobe):
            return lobe.at[0].add(0.01)

    class Analyser(Effect):
        name = "analyser"

        def modify_stokes(self, ctx, total):
            return total.at[0].add(0.005)

    class Sheen(Effect):
        name = "sheen"

        def lobe(self, ctx):
            cos = ctx.geometry.cos_tr * jnp.ones(ctx.shape)
            return jnp.stack([0.02 * cos, -0.01 * cos, 0.003 * cos, 0.0 * cos])

    g = Geometry(np.array([30.0, 45.0, 60.0, 10.0]), np.array([20.0, 60.0, 75.0, 10.0]), np.array([180.0, 180.0, 150.0, 0.0]))
    sets = {"ks": np.array([0.3, 0.6, 0.05]), "n": np.array([1.5, 0.9, 2.4]), "k": np.array([0.0, 3.0, 0.01])}
    base = Model.from_string("paper")
    dops = {}
    for plugin in (HalfS1(), Analyser(), Sheen()):
        model = Model([*base.effects, plugin])
        dops[plugin.name] = model.dop(sets, g)
        np.testing.assert_allclose(dops[plugin.name], model.evaluate(sets, g).dop, rtol=1e-13, atol=1e-15, err_msg=plugin.name)
    for name, dop in dops.items():  # negative control: each plug-in changes the DOP
        assert np.max(np.abs(dop - base.dop(sets, g))) > 1e-4, name


def test_the_dop_of_one_polarized_lobe_takes_no_square_root_of_its_own():
    """The specular lobe leaves polarized along one direction, (S1, S2) = s1 (cos 2 eta, -sin 2 eta), so the DOP
    program takes |S_pol| = |s1| (``effect.Ratio.polarized``) instead of sqrt(S1^2 + S2^2): equal to evaluate's
    DOP, which takes the root, out of the plane, at normal incidence, in retro-reflection, at the specular peak
    and below the horizon; a depolarized lobe keeps the shortcut, a polarized plug-in lobe drops it (negative
    control: that program takes the root again)."""
    from spacepol.physics.compiled import evaluate_values
    from spacepol.physics.effect import Effect

    class Sheen(Effect):  # polarized: the sum is no longer polarized along one direction
        name = "sheen"

        def lobe(self, ctx):
            cos = ctx.geometry.cos_tr * jnp.ones(ctx.shape)
            return jnp.stack([0.02 * cos, -0.01 * cos, 0.003 * cos, 0.0 * cos])

    rng = np.random.default_rng(11)
    ti = np.concatenate([rng.uniform(0, 85, 40), [0.0, 30.0, 30.0, 45.0, 60.0, 95.0]])
    tr = np.concatenate([rng.uniform(0, 85, 40), [0.0, 30.0, 30.0, 45.0, 100.0, 20.0]])
    dphi = np.concatenate([rng.uniform(-180, 180, 40), [0.0, 0.0, 180.0, 90.0, 180.0, 180.0]])
    g = Geometry(ti, tr, dphi)
    assert not g.all_visible
    sets = {"n": np.array([1.5, 0.9, 2.4, 1.0001]), "k": np.array([0.0, 3.0, 0.01, 0.0]), "sigma": np.array([0.1, 0.3, 0.5, 0.05])}

    def square_roots(model):
        values, batch = model._resolve(sets, False)
        program = jax.make_jaxpr(lambda v: evaluate_values(model.effects, v, batch, Geometry.from_terms(g.device_terms(), False),
                                                           False, up_to_scale=True)[1])
        return str(program(values)).count(" sqrt ")

    counts = {}
    for spec in ("paper", "paper+lambertian", "paper+polarized_diffuse"):
        model = Model.from_string(spec)
        np.testing.assert_allclose(model.dop(sets, g), model.evaluate(sets, g).dop, rtol=1e-13, atol=1e-15, err_msg=spec)
        counts[spec] = square_roots(model)
    sheen = Model([*Model.from_string("paper").effects, Sheen()])
    np.testing.assert_allclose(sheen.dop(sets, g), sheen.evaluate(sets, g).dop, rtol=1e-13, atol=1e-15)
    assert counts["paper"] == counts["paper+lambertian"] == square_roots(sheen) - 1, (counts, square_roots(sheen))
