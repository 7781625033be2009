"""fmpy checks of the PlateImpact FMUs (the `plate_impact` scene: a flyer
plate on a target plate in uniaxial strain; FMI 3.0 and FMI 2.0
Co-Simulation), as the other FMUs are: `fmpy validate` and `fmutool
-check`; the variables are the scene's parameter and observable tables; a
run with parameters set (a metal flyer on the ceramic, a ceramic constant
changed) gives the command line's final values bit for bit; the FMU state
rolls back exactly and moves between instances; bad values and plates too
finely cut are refused with their names.

Every run is coarse and short: 40 um cells (150 cells), 1.5 us."""

import pytest
from fmpy import simulate_fmu

from conftest import assert_simulated_equal_to_cli, assert_variables_are_the_scene_tables, check_fmu_file, cli_json, model
from test_fmu import assert_initialization_refused, assert_set_refused, assert_state_rolls_back_and_resumes, init2, init3, slave2, slave3

ID = "PlateImpact"
COARSE = {"cell": 4e-5, "end_time": 1.5e-6}


def fmu(suffix=""):
    return model(ID, suffix)


def cli_plate(tmp_path_factory, params):
    """Final values of `meshless-impact run plate_impact` with `params`."""
    sets = [a for name, value in params.items() for a in ("--set", f"{name}={value!r}")]
    return cli_json(tmp_path_factory, "plate_impact", *sets)


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_validate_and_fmutool_check(suffix):
    check_fmu_file(fmu(suffix).path)


def test_variables_are_the_scene_tables():
    m3, observables = assert_variables_are_the_scene_tables(ID, "plate_impact")
    assert {"free_surface_velocity", "precursor_stress", "spall_strength", "energy_error"} <= set(observables)
    params = {v.name for v in m3.md.modelVariables if v.causality == "parameter"}
    assert {"impact_speed", "flyer_material", "target_thickness", "plate_crack_size", "cell"} <= params
    assert m3.var("flyer_material").type == "Enumeration"
    units = {u.name: u for u in m3.md.unitDefinitions}
    assert units["J/m2"].baseUnit.kg == 1 and units["J/m2"].baseUnit.s == -2 and units["J/m2"].baseUnit.m == 0


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_a_run_with_parameters_set_equals_the_cli(suffix, tmp_path_factory):
    """A tungsten flyer (level 3, `tungsten_seed`) on the ceramic with a
    larger initial crack: the CLI's final values bit for bit."""
    m = fmu(suffix)
    start = {**COARSE, "impact_speed": 250.0, "flyer_material": 3, "plate_crack_size": 2e-5}
    ref = cli_plate(tmp_path_factory, start)
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=start, output=names, stop_time=1.5e-6, output_interval=1e-7)
    assert_simulated_equal_to_cli(r, ref, names)
    # The free surface has moved, and the run conserved energy.
    assert ref["peak_velocity"] > 0.5 * 250.0
    assert 0.0 <= ref["energy_error"] < 0.01
    assert ref["peak_velocity"] != cli_plate(tmp_path_factory, COARSE)["peak_velocity"]


def test_fmu_state_rolls_back_and_moves_between_instances(tmp_path_factory):
    ref = cli_plate(tmp_path_factory, COARSE)
    assert_state_rolls_back_and_resumes(fmu(), init3, COARSE, 2e-7, 3, ref)
    assert_state_rolls_back_and_resumes(fmu("_fmi2"), init2, COARSE, 2e-7, 3, ref)
    assert 1.5e-6 <= ref["end_time"] < 1.6e-6


def test_bad_values_are_refused_with_their_names():
    for m, make in ((fmu(), slave3), (fmu("_fmi2"), slave2)):
        for name, value, needle in [
            ("flyer_material", 99, "parameter `flyer_material` = 99 is out of range"),
            ("target_thickness", -0.001, "parameter `target_thickness` = -0.001 is out of range"),
            ("impact_speed", float("nan"), "parameter `impact_speed` = NaN is out of range"),
        ]:
            assert_set_refused(m, make, {name: value}, needle)
        assert_initialization_refused(m, make, {"target_thickness": 0.1, "flyer_thickness": 0.1, "cell": 1e-7},
                                      "raise cell")
