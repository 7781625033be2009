"""fmpy checks of the Taylor3dImpact FMUs (the `taylor3d` scene, 3-D MLPG;
FMI 3.0 and FMI 2.0 Co-Simulation), as the TaylorImpact checks are, at 3
nodes across the radius (399 nodes, about 2 s a run to rest): `fmpy
validate` and `fmutool -check`; the variables are the scene's parameter and
observable tables (the CLI's `params taylor3d` and `observables taylor3d`);
a run with a parameter set gives the command line's final values bit for
bit, through FMI 3 and FMI 2; the FMU state rolls back exactly and moves
between instances; the early stop; a bad value and a foreign state are
refused with their names."""

import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Discard, fmi2LastSuccessfulTime, fmi2Terminated

from conftest import assert_simulated_equal_to_cli, check_fmu_file, cli, cli_json, model, params_of
from test_fmu import MESSAGES, assert_set_refused, init2, init3, messages, outputs, slave2, slave3

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
    m3, m2 = fmu(), fmu("_fmi2")
    want = params_of("taylor3d")
    params = [v for v in m3.md.modelVariables if v.causality == "parameter"]
    assert [v.name for v in params] == [n for n, _ in want]
    assert [float(v.start) for v in params] == [v for _, v in want]
    assert [v.name for v in m2.md.modelVariables if v.causality == "parameter"] == [n for n, _ in want]
    assert m3.var("particles_radial").type == "Int32" and m2.var("particles_radial").type == "Integer"
    observables = [line.split()[0] for line in cli("observables", "taylor3d").splitlines()]
    assert [v.name for v in m3.outputs] == observables
    assert [v.name for v in m2.outputs] == observables
    assert {"rod_length", "mushroom_radius", "mushroom_radius_spread", "energy_error"} <= set(observables)
    assert m3.var("at_rest").type == "Boolean"
    # Value references: time 0 (FMI 3), the parameters from 1, then the outputs.
    assert [v.valueReference for v in m3.md.modelVariables] == list(range(len(m3.md.modelVariables)))
    assert m3.md.coSimulation.modelIdentifier == ID == m2.md.coSimulation.modelIdentifier
    taylor = model("TaylorImpact")
    assert m3.md.guid == m2.md.guid != taylor.md.guid


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
    if suffix == "_fmi2":
        # fmi2Discard at the last successful time: the moment of rest.
        assert r["time"][-1] == ref["end_time"]
    else:
        assert r["time"][-1] >= ref["end_time"]
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
    step = 1e-6
    for m, init in ((fmu(), init3), (fmu("_fmi2"), init2)):
        s = init(m, {"particles_radial": NODES})
        for n in range(10):
            s.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
        fmi3 = init is init3
        state = s.getFMUState() if fmi3 else s.getFMUstate()
        s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
        after = outputs(s, m)
        s.doStep(currentCommunicationPoint=11 * step, communicationStepSize=step)
        assert outputs(s, m) != after
        (s.setFMUState if fmi3 else s.setFMUstate)(state)
        s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
        assert outputs(s, m) == after
        data = (s.serializeFMUState if fmi3 else s.serializeFMUstate)(state)
        assert bytes(data).startswith(b"Taylor3dImpact FMU state v2 postcard\n")
        t = slave3(m, name="copy") if fmi3 else slave2(m, name="copy")
        restored = (t.deserializeFMUState if fmi3 else t.deSerializeFMUstate)(data)
        (t.setFMUState if fmi3 else t.setFMUstate)(restored)
        n = 10
        while True:
            try:
                r = t.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
            except FMICallException as e:  # FMI 2: the early stop
                assert not fmi3 and e.status == fmi2Discard
                break
            n += 1
            if fmi3 and r[1]:
                break
        out = outputs(t, m)
        for name, value in out.items():
            assert value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"
        if not fmi3:
            assert t.getBooleanStatus(fmi2Terminated)
            assert t.getRealStatus(fmi2LastSuccessfulTime) == ref["end_time"]
        for x in (s, t):
            x.freeInstance()


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
