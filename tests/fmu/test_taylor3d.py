"""fmpy checks of the Taylor3dImpact FMUs (the `taylor3d` scene, 3-D MLPG;
FMI 3.0 and FMI 2.0 Co-Simulation), as the TaylorImpact checks are, at 3
nodes across the radius (399 nodes, about 2 s a run to rest): `fmpy
validate` and `fmutool -check`; the variables are the scene's parameter and
observable tables (the CLI's `params taylor3d` and `observables taylor3d`);
a run with a parameter set gives the command line's final values bit for
bit, through FMI 3 and FMI 2; the FMU state rolls back exactly and moves
between instances; the steps past the rest; a bad value and a foreign state are
refused with their names."""

import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from conftest import (assert_simulated_equal_to_cli, assert_variables_are_the_scene_tables, check_fmu_file, cli_json,
                      model)
from test_fmu import (MESSAGES, assert_held_past_the_end, assert_set_refused, assert_state_rolls_back_and_resumes,
                      init2, init3, messages, slave2, slave3)

ID = "Taylor3dImpact"
NODES = 3  # particles_radial: 3 nodes across the radius, 2 rings


def fmu(suffix=""):
    return model(ID, suffix)


def cli3d(tmp_path_factory, *sets):
    """Final values of `meshless-impact run taylor3d` at NODES across."""
    args = ["taylor3d", "--set", f"particles_radial={NODES}"]
    for s in sets:
        args += ["--set", s]
    return cli_json(tmp_path_factory, *args)


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_validate_and_fmutool_check(suffix):
    check_fmu_file(fmu(suffix).path)


def test_variables_are_the_scene_tables():
    m3, observables = assert_variables_are_the_scene_tables(ID, "taylor3d")
    assert {"rod_length", "mushroom_radius", "mushroom_radius_spread", "energy_error"} <= set(observables)
    assert m3.var("at_rest").type == "Boolean"
    assert m3.md.guid != model("TaylorImpact").md.guid


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
def test_a_run_with_a_parameter_set_equals_the_cli(suffix, tmp_path_factory):
    """A slower, stronger rod: to rest, bit for bit, and longer than the
    default rod. (At 3 nodes across, 200 m/s already stops with a spacing
    collapse: the stability matrix's 3-D rows.)"""
    m = fmu(suffix)
    start = {"particles_radial": NODES, "impact_speed": 160.0, "jc_a": 850e6}
    ref = cli3d(tmp_path_factory, "impact_speed=160", "jc_a=850e6")
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=start, output=names)
    assert_simulated_equal_to_cli(r, ref, names)
    assert ref["at_rest"] is True
    # Both run on past the rest to stopTime (400 us), the outputs held;
    # at_rest comes at the communication point whose step reached rest:
    # within one communication step (1 us) of the moment of rest (a solver
    # step is not shortened at a communication point).
    assert_held_past_the_end(r, ref, 400e-6)
    assert ref["rod_length"] < 0.03797
    assert ref["mushroom_radius"] > 0.5 * 0.007595
    assert 0.0 <= ref["mushroom_radius_spread"] < 0.05 and 0.0 <= ref["energy_error"] < 0.05
    assert ref["rod_length"] > cli3d(tmp_path_factory)["rod_length"]


def test_a_short_stop_time_ends_there_with_the_clis_values(tmp_path_factory):
    """stop_time (and end_time) 10 us: the outputs of the CLI run that ends
    at end_time = 10 us, bit for bit, and the rod still moving."""
    ref = cli3d(tmp_path_factory, "end_time=1e-5")
    m = fmu()
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values={"particles_radial": NODES, "end_time": 1e-5},
                     output=names, stop_time=1e-5, output_interval=1e-6)
    assert_simulated_equal_to_cli(r, ref, names)
    assert ref["at_rest"] is False and ref["tail_velocity"] > 100.0
    assert len(r) >= 10


def test_fmu_state_rolls_back_and_moves_between_instances(tmp_path_factory):
    """FMI 3 and FMI 2: a state got at 10 us and set again steps to the same
    outputs; its bytes, in a new instance, run to the end with the CLI's
    final values bit for bit."""
    ref = cli3d(tmp_path_factory)
    assert_state_rolls_back_and_resumes(fmu(), init3, {"particles_radial": NODES}, 1e-6, 10, ref)
    assert_state_rolls_back_and_resumes(fmu("_fmi2"), init2, {"particles_radial": NODES}, 1e-6, 10, ref)


def test_bad_values_and_foreign_states_are_refused_with_their_names():
    for m, make in ((fmu(), slave3), (fmu("_fmi2"), slave2)):
        for name, value, needle in [
            ("particles_radial", 2, "parameter `particles_radial` = 2 is out of range"),
            ("damping", 0.9, "parameter `damping` = 0.9 is out of range"),
            ("impact_speed", float("nan"), "parameter `impact_speed` = NaN is out of range"),
        ]:
            assert_set_refused(m, make, {name: value}, needle)
    # A TaylorImpact state into Taylor3dImpact and the other way.
    taylor = model("TaylorImpact")
    states = {}
    for m in (taylor, fmu()):
        s = init3(m, {"particles_radial": 4})
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
        state = s.getFMUState()
        states[m.md.coSimulation.modelIdentifier] = bytes(s.serializeFMUState(state))
        s.freeFMUState(state)
        s.freeInstance()
    for m, other in ((fmu(), "TaylorImpact"), (taylor, ID)):
        t = slave3(m, name="foreign")
        MESSAGES.clear()
        with pytest.raises(FMICallException):
            t.deserializeFMUState(states[other])
        mine = m.md.coSimulation.modelIdentifier
        assert any(f"not a serialized {mine} FMU state" in x for x in messages("logStatusError")), MESSAGES
        t.freeInstance()


@pytest.mark.parametrize("make", [slave3, slave2])
def test_a_rod_over_the_memory_budget_is_refused_at_initialization(make):
    """Issue 48, failure 2: `initial_diameter = 1e-4` killed the fmpy host
    process on allocation (345 000 nodes at 6 across, whose support search
    took 190 spacings; now about 5 GB, under the budget). At 10 across the
    same rod has 1.85 million nodes: the memory budget refuses it at
    initialization with Error and a message that gives the node count and
    the budget, before anything is allocated."""
    from test_fmu import assert_initialization_refused
    assert_initialization_refused(fmu("" if make is slave3 else "_fmi2"), make,
                                  {"initial_diameter": 1e-4, "particles_radial": 10}, "memory budget")
