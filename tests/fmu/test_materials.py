"""fmpy checks of the FMUs of the other material choices of the `taylor`
scene: one FMU per choice (README, "Materials"). Each must pass `fmpy
validate` and `fmutool -check`, list exactly the parameters of its models
(the CLI's `params --strength ... --eos ...`), and give the final
observables of the command-line program on the same scene, bit for bit.
A preset reaches an FMU as start values: the Wilkins bar of
scenes/wilkins_copper_bilinear.toml through TaylorImpactBilinear equals the
CLI run of that scene file."""

from pathlib import Path

import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import COARSE, ROOT, assert_simulated_equal_to_cli, check_fmu_file, cli_json, model, params_of

CHOICES = [
    ("TaylorImpactBilinear", "bilinear", "linear"),
    ("TaylorImpactMieGruneisen", "johnson_cook", "mie_gruneisen"),
    ("TaylorImpactBilinearMieGruneisen", "bilinear", "mie_gruneisen"),
]


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
@pytest.mark.parametrize("identifier,strength,eos", CHOICES)
def test_validate_and_fmutool_check(identifier, strength, eos, suffix):
    check_fmu_file(model(identifier, suffix).path)


@pytest.mark.parametrize("identifier,strength,eos", CHOICES)
def test_variables_are_the_choice_parameters(identifier, strength, eos):
    m3, m2 = model(identifier, ""), model(identifier, "_fmi2")
    want = params_of("--strength", strength, "--eos", eos)
    params = [v for v in m3.md.modelVariables if v.causality == "parameter"]
    assert [v.name for v in params] == [n for n, _ in want]
    assert [float(v.start) for v in params] == [v for _, v in want]
    names = {v.name for v in params}
    if strength == "bilinear":
        assert {"yield_stress", "hardening_modulus"} <= names and not any(n.startswith("jc_") for n in names)
    if eos == "mie_gruneisen":
        assert {"eos_c0", "eos_s", "gruneisen"} <= names and "bulk_modulus" not in names
    # The outputs are the Taylor scene's; the tokens differ from TaylorImpact's.
    base = read_model_description(str(ROOT / "target" / "fmu" / "TaylorImpact.fmu"))
    assert [v.name for v in m3.outputs] == [v.name for v in base.modelVariables if v.causality == "output"]
    assert m3.md.guid == m2.md.guid != base.guid


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
@pytest.mark.parametrize("identifier,strength,eos", CHOICES)
def test_coarse_run_equals_the_cli(identifier, strength, eos, suffix, tmp_path_factory):
    m = model(identifier, suffix)
    ref = cli_json(tmp_path_factory, "--strength", strength, "--eos", eos, "--set", f"particles_radial={COARSE}")
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values={"particles_radial": COARSE}, output=names)
    assert_simulated_equal_to_cli(r, ref, names)
    assert ref["at_rest"] is True


def test_preset_as_start_values_equals_the_scene_file(tmp_path_factory):
    """The Wilkins bar through TaylorImpactBilinear, its preset and
    parameters given as start values, equals the CLI run of
    scenes/wilkins_copper_bilinear.toml."""
    scene = str(ROOT / "scenes" / "wilkins_copper_bilinear.toml")
    ref = cli_json(tmp_path_factory, "--scene-file", scene, "--set", f"particles_radial={COARSE}")
    m = model("TaylorImpactBilinear", "")
    start = dict(params_of("--preset", "copper_wilkins_bilinear"))
    for line in Path(scene).read_text().split("[parameters]")[1].split("[reference]")[0].splitlines():
        if "=" in line:
            name, value = line.split("#")[0].split("=")
            start[name.strip()] = float(value)
    start["particles_radial"] = COARSE
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=start, output=names, stop_time=400e-6)
    assert_simulated_equal_to_cli(r, ref, names)
    assert ref["at_rest"] is True
    assert start["yield_stress"] == 400e6 and start["hardening_modulus"] == 100e6
