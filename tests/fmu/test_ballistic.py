"""fmpy checks of the BallisticImpact FMUs (the `penetration` scene, 3-D
MLPG with two bodies; FMI 3.0 and FMI 2.0 Co-Simulation), as the
TaylorImpact and Taylor3dImpact checks are: `fmpy validate` and `fmutool
-check`; the variables are the scene's parameter and observable tables (the
CLI's `params penetration` and `observables penetration`); a run with
parameters set gives the command line's final values bit for bit, through
FMI 3 and FMI 2; the FMU state rolls back exactly and moves between
instances; a solver stop is an Error with the solver's message and the
outputs of the command line at the stop; bad values, an inconsistent plate
and a foreign state are refused with their names.

Every run is coarse and short: 3 nodes across the projectile's radius, a
plate 20 mm across (278 nodes), 2 or 4 µs (some 10 ms a run); the solver stop is a 2 mm projectile at 2 nodes across (204 nodes)."""

import json
import math
import subprocess

import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from conftest import (CLI, assert_simulated_equal_to_cli, assert_variables_are_the_scene_tables, check_fmu_file,
                      cli_json, model)
from test_fmu import (MESSAGES, assert_initialization_refused, assert_set_refused, assert_state_rolls_back_and_resumes,
                      init2, init3, messages, outputs, slave2, slave3)

ID = "BallisticImpact"
# 3 nodes across the projectile's radius (spacing 2.5 mm), a plate 20 mm
# across.
COARSE = {"particles_radial": 3, "plate_diameter": 0.02}
# Stops with a spacing collapse at 1.78 us (2 nodes across a 2 mm projectile
# at 1500 m/s on a 2 mm plate 8 mm across).
# The solver's choices of the scene before 2026-11-26 (the seed's test
# spheres, no smoothing, no shifting), under which this case stops.
PLAIN = {"weak_form": 0, "smoothing_order": 1, "smoothing_coefficient": 0.0, "shifting": 0.0}
STOPS = {"particles_radial": 2, "projectile_diameter": 0.002, "projectile_length": 0.002,
         "plate_thickness": 0.002, "plate_diameter": 0.008, "impact_speed": 1500.0, "end_time": 4e-6, **PLAIN}


def fmu(suffix=""):
    return model(ID, suffix)


def sets(params):
    return [a for name, value in params.items() for a in ("--set", f"{name}={value!r}")]


def cli_pen(tmp_path_factory, params):
    """Final values of `meshless-impact run penetration` with `params`."""
    return cli_json(tmp_path_factory, "penetration", *sets(params))


def cli_stop(tmp_path, params):
    """A `meshless-impact run penetration` that stops with an error: its
    message and the values it wrote at the stop."""
    out = tmp_path / "stop.json"
    r = subprocess.run([str(CLI), "run", "penetration", "-q", *sets(params), "--json", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    return r.stderr.strip().removeprefix("error: "), json.loads(out.read_text())


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_validate_and_fmutool_check(suffix):
    check_fmu_file(fmu(suffix).path)


def test_variables_are_the_scene_tables():
    m3, observables = assert_variables_are_the_scene_tables(ID, "penetration")
    assert {"projectile_velocity", "projectile_extent", "projectile_clearance", "hole_radius", "damaged_fraction", "pulverized_fraction",
            "max_damage", "energy_error"} <= set(observables)
    assert all(v.type == "Float64" for v in m3.outputs)
    # The initial length is a parameter, the current one an output: FMI
    # names are unique.
    assert m3.var("projectile_length").causality == "parameter"
    params = {v.name for v in m3.md.modelVariables if v.causality == "parameter"}
    assert {"impact_speed", "plate_thickness", "plate_rg_c1", "projectile_yield_stress"} <= params
    assert m3.md.guid != model("Taylor3dImpact").md.guid
    # K_IC's unit has a fractional exponent: declared by name alone.
    units = {u.name: u for u in m3.md.unitDefinitions}
    assert m3.var("plate_fracture_toughness").unit == "Pa.m^(1/2)"
    assert units["Pa.m^(1/2)"].baseUnit is None
    assert units["1/m3"].baseUnit.m == -3 and units["1/m3"].baseUnit.kg == 0


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_a_run_with_parameters_set_equals_the_cli(suffix, tmp_path_factory):
    """Impact speed, plate thickness and a constant of each material set:
    the CLI's final values bit for bit, at the end time."""
    m = fmu(suffix)
    start = {**COARSE, "end_time": 2e-6, "impact_speed": 1200.0, "plate_thickness": 0.006,
             "plate_rg_c1": 3.5e9, "projectile_yield_stress": 1.2e9}
    ref = cli_pen(tmp_path_factory, start)
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=start, output=names, stop_time=2e-6, output_interval=2e-7)
    assert_simulated_equal_to_cli(r, ref, names)
    assert len(r) >= 10
    # The projectile slows in the plate, which cracks.
    assert 0.5 * 1200.0 < ref["projectile_velocity"] < 1200.0
    assert ref["projectile_extent"] < 0.01
    assert 0.0 < ref["damaged_fraction"] <= 1.0 and ref["max_damage"] > 0.0
    assert 0.0 <= ref["energy_error"] < 0.05
    assert ref["projectile_velocity"] != cli_pen(tmp_path_factory, {**COARSE, "end_time": 2e-6})["projectile_velocity"]


def test_fmu_state_rolls_back_and_moves_between_instances(tmp_path_factory):
    """FMI 3 and FMI 2: a state got at 1.5 us and set again steps to the same
    outputs; its bytes, in a new instance, run to the end (4 us) with the
    CLI's final values bit for bit."""
    params = {**COARSE, "end_time": 4e-6}
    ref = cli_pen(tmp_path_factory, params)
    assert_state_rolls_back_and_resumes(fmu(), init3, params, 5e-7, 3, ref)
    assert_state_rolls_back_and_resumes(fmu("_fmi2"), init2, params, 5e-7, 3, ref)
    assert 4e-6 <= ref["end_time"] < 4.1e-6


def test_the_quarter_model_through_the_fmu(tmp_path_factory):
    """`symmetry` = 1 reaches the run: the FMU gives the CLI's quarter model
    bit for bit (92 nodes against the whole body's 278), its state rolls
    back and moves between instances, and its projectile is within the
    issue's 1 % of the whole body's (measured 1305.4 against 1306.8 m/s,
    -0.11 %, at 4 us)."""
    quarter = {**COARSE, "end_time": 4e-6, "symmetry": 1}
    ref = cli_pen(tmp_path_factory, quarter)
    whole = cli_pen(tmp_path_factory, {**COARSE, "end_time": 4e-6})
    assert ref["particles"] == 92 and whole["particles"] == 278
    assert abs(ref["projectile_velocity"] / whole["projectile_velocity"] - 1.0) < 0.01
    m = fmu()
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=quarter, output=names, stop_time=4e-6, output_interval=4e-7)
    assert_simulated_equal_to_cli(r, ref, names)
    assert_state_rolls_back_and_resumes(fmu(), init3, quarter, 5e-7, 3, ref)


def test_a_solver_stop_is_an_error_with_the_clis_message_and_values(tmp_path):
    """The run that collapses a spacing: Error from doStep, the CLI's message
    in the host's log, and the outputs at the stop equal the CLI's bit for
    bit (what examples/ballistic_limit.py reports for such a shot)."""
    message, ref = cli_stop(tmp_path, STOPS)
    assert message.startswith("particle spacing collapsed"), message
    for m, init in ((fmu(), init3), (fmu("_fmi2"), init2)):
        s = init(m, STOPS)
        MESSAGES.clear()
        with pytest.raises(FMICallException) as e:
            for n in range(40):
                s.doStep(currentCommunicationPoint=n * 1e-7, communicationStepSize=1e-7)
        assert e.value.status == 3
        assert any(x.endswith(f"DoStep: the solver stopped: {message}") for x in messages("logStatusError")), MESSAGES
        for name, value in outputs(s, m).items():
            assert math.isfinite(value) and value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"
        s.freeInstance()


def test_bad_values_and_foreign_states_are_refused_with_their_names():
    for m, make in ((fmu(), slave3), (fmu("_fmi2"), slave2)):
        for name, value, needle in [
            ("particles_radial", 1, "parameter `particles_radial` = 1 is out of range"),
            ("plate_thickness", -0.001, "parameter `plate_thickness` = -0.001 is out of range"),
            ("plate_porosity", 0.7, "parameter `plate_porosity` = 0.7 is out of range"),
            ("impact_speed", float("nan"), "parameter `impact_speed` = NaN is out of range"),
        ]:
            assert_set_refused(m, make, {name: value}, needle)
        # A plate no wider than the projectile: refused at initialization.
        assert_initialization_refused(m, make, {"plate_diameter": 0.01},
                                      "plate_diameter = 0.01 must exceed projectile_diameter")
    # A Taylor3dImpact state into BallisticImpact.
    other = model("Taylor3dImpact")
    s = init3(other, {"particles_radial": 3})
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
    state = s.getFMUState()
    data = bytes(s.serializeFMUState(state))
    s.freeFMUState(state)
    s.freeInstance()
    t = slave3(fmu(), name="foreign")
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        t.deserializeFMUState(data)
    assert any(f"not a serialized {ID} FMU state" in x for x in messages("logStatusError")), MESSAGES
    t.freeInstance()
