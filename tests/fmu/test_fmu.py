"""fmpy checks of the TaylorImpact FMUs (FMI 3.0 and FMI 2.0 Co-Simulation).

Reference values come from the command-line program on the same scene
(`meshless-impact run --json`): the FMU drives the same core, so the final
observables must be bit-identical. Everything except the one equality check at
the defaults runs at particles_radial = 6 (see conftest.COARSE)."""

import json
import math
import subprocess
import sys
import threading
from pathlib import Path
from ctypes import byref

import fmpy
import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2DoStepStatus,
    fmi2LastSuccessfulTime,
    fmi2OK,
    fmi2Terminated,
)
from fmpy.fmi3 import FMU3Slave

from conftest import COARSE, check_fmu_file, cli_run

# ---------------------------------------------------------------- loggers
# One logger of each kind for the whole process (fmpy keeps one per process);
# each test reads the messages it caused by clearing MESSAGES first.
MESSAGES = []


def _log3(env, status, category, message):
    MESSAGES.append((status, category.decode(), message.decode()))


def _log2(env, instance_name, status, category, message):
    MESSAGES.append((status, category.decode(), message.decode()))


CALLBACKS2 = fmi2CallbackFunctions()
CALLBACKS2.logger = fmi2CallbackLoggerTYPE(_log2)
CALLBACKS2.allocateMemory = fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
CALLBACKS2.freeMemory = fmi2CallbackFreeMemoryTYPE(fmpy.free)
try:
    from fmpy.logging import addLoggerProxy

    addLoggerProxy(byref(CALLBACKS2))  # formats the printf-style FMI 2 message
except Exception:  # pragma: no cover - fmpy without the proxy library
    pass


def messages(category=None):
    return [m for (_, c, m) in MESSAGES if category is None or c == category]


# ---------------------------------------------------------------- drivers
def slave3(m, name="a", logging_on=False, early_return=False):
    s = FMU3Slave(guid=m.md.guid, unzipDirectory=m.unzipdir,
                  modelIdentifier=m.md.coSimulation.modelIdentifier, instanceName=name)
    s.instantiate(loggingOn=logging_on, earlyReturnAllowed=early_return, logMessage=_log3)
    return s


def slave2(m, name="a", logging_on=False):
    s = FMU2Slave(guid=m.md.guid, unzipDirectory=m.unzipdir,
                  modelIdentifier=m.md.coSimulation.modelIdentifier, instanceName=name)
    s.instantiate(callbacks=CALLBACKS2, loggingOn=logging_on)
    return s


def set_params(s, m, params):
    for name, value in params.items():
        v = m.var(name)
        if v.type == "Enumeration":  # FMI 3 (the scheme); FMI 2 declares it an Integer
            s.setInt64([v.valueReference], [int(value)])
        elif v.type in ("Int32", "Integer"):
            (s.setInt32 if hasattr(s, "setInt32") else s.setInteger)([v.valueReference], [int(value)])
        else:
            (s.setFloat64 if hasattr(s, "setFloat64") else s.setReal)([v.valueReference], [float(value)])


def assert_set_refused(m, make, params, needle):
    """Setting `params` on a new instance (`make(m)`: slave3 or slave2) is
    refused with Error, and the host's log has an error containing
    `needle`."""
    s = make(m)
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        set_params(s, m, params)
    assert any(needle in x for x in messages("logStatusError")), MESSAGES
    s.freeInstance()


def assert_initialization_refused(m, make, params, needle):
    """A new instance (`make(m)`: slave3 or slave2) with `params` set fails
    to initialize with Error, and the host's log has a message containing
    `needle`."""
    s = make(m)
    set_params(s, m, params)
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        if make is slave3:
            s.enterInitializationMode(startTime=0.0)
        else:
            s.setupExperiment(startTime=0.0)
            s.enterInitializationMode()
        s.exitInitializationMode()
    assert any(needle in x for x in messages()), MESSAGES
    s.freeInstance()


def outputs(s, m):
    out = {}
    for v in m.outputs:
        if v.type == "Boolean":
            out[v.name] = bool(s.getBoolean([v.valueReference])[0])
        elif hasattr(s, "getFloat64"):
            out[v.name] = s.getFloat64([v.valueReference])[0]
        else:
            out[v.name] = s.getReal([v.valueReference])[0]
    return out


def init3(m, params, **kw):
    s = slave3(m, **kw)
    set_params(s, m, params)
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    return s


def init2(m, params, **kw):
    s = slave2(m, **kw)
    set_params(s, m, params)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    return s


def step_past_the_end(s, m, step=1e-6, t0=0.0, end=None):
    """Steps `s` (FMI 3 or FMI 2) from `t0` by `step` until its scene has
    ended (the output `at_rest`, or the time `end`: the CLI's end time), and
    once more. Every step completes: FMI 3 answers no event, no request to
    stop, no early return and the end of the step as lastSuccessfulTime;
    FMI 2 answers OK (fmpy raises otherwise), its status is OK and not
    Terminated. The outputs of the last step are those of the one before
    (they hold past the scene's end). Returns the outputs and the number of
    steps."""
    fmi3 = hasattr(s, "getFloat64")
    rest = next((v.valueReference for v in m.outputs if v.name == "at_rest"), None)
    n, ended = 0, False
    while True:
        t = t0 + n * step
        r = s.doStep(currentCommunicationPoint=t, communicationStepSize=step)
        n += 1
        if fmi3:
            event, terminate, early, last = r
            assert (event, terminate, early, last) == (False, False, False, t + step), r
        else:
            assert s.getStatus(fmi2DoStepStatus) == fmi2OK
            assert not s.getBooleanStatus(fmi2Terminated)
            assert s.getRealStatus(fmi2LastSuccessfulTime) == t + step
        if ended:
            assert outputs(s, m) == held
            return held, n
        ended = (end is not None and t + step >= end) or (rest is not None and bool(s.getBoolean([rest])[0]))
        if ended:
            held = outputs(s, m)


def run3(m, params, step=1e-6, **kw):
    """Steps an FMI 3 instance past the end of its scene; final outputs."""
    s = init3(m, params, **kw)
    out, _ = step_past_the_end(s, m, step)
    s.terminate()
    s.freeInstance()
    return out


def assert_state_rolls_back_and_resumes(m, init, params, step, k, ref):
    """Through FMI 3 (`init` = init3) or FMI 2 (init2), with `params`: a
    state got after `k` steps of `step` and set again steps to the same
    outputs; its serialized bytes (headed by the FMU's state header), in a
    new instance, run on to the end with the final values `ref` bit for
    bit, and hold them past the scene's end with every step complete."""
    fmi3 = init is init3
    s = init(m, params)
    for n in range(k):
        s.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
    state = s.getFMUState() if fmi3 else s.getFMUstate()
    s.doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
    after = outputs(s, m)
    s.doStep(currentCommunicationPoint=(k + 1) * step, communicationStepSize=step)
    assert outputs(s, m) != after
    (s.setFMUState if fmi3 else s.setFMUstate)(state)
    s.doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
    assert outputs(s, m) == after
    data = (s.serializeFMUState if fmi3 else s.serializeFMUstate)(state)
    header = f"{m.md.coSimulation.modelIdentifier} FMU state v2 postcard\n"
    assert bytes(data).startswith(header.encode())
    t = slave3(m, name="copy") if fmi3 else slave2(m, name="copy")
    restored = (t.deserializeFMUState if fmi3 else t.deSerializeFMUstate)(data)
    (t.setFMUState if fmi3 else t.setFMUstate)(restored)
    # On past the end of the scene, every step complete, the outputs held.
    held, _ = step_past_the_end(t, m, step, t0=k * step, end=ref["end_time"])
    for name, value in held.items():
        assert value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"
    for x in (s, t):
        x.freeInstance()


def coarse_cli(tmp_path_factory, *sets):
    return cli_run(tmp_path_factory, f"particles_radial={COARSE}", *sets)


def assert_equal_to_cli(out, ref):
    for name, value in out.items():
        if name == "at_rest":
            assert value is True and ref[name] is True
        else:
            assert value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"


# ---------------------------------------------------------------- checks
@pytest.mark.parametrize("which", ["fmu3", "fmu2"])
def test_fmpy_validate_and_fmutool_check(which, request):
    check_fmu_file(request.getfixturevalue(which).path)


def test_variables_match_the_tables(fmu3, fmu2, tmp_path_factory):
    names3 = {v.name for v in fmu3.md.modelVariables}
    names2 = {v.name for v in fmu2.md.modelVariables}
    assert names3 - names2 == {"time"}
    params = [v for v in fmu3.md.modelVariables if v.causality == "parameter"]
    assert len(params) == 24
    assert all(v.variability == "fixed" and v.start is not None for v in params)
    assert fmu3.var("particles_radial").type == "Int32" and fmu2.var("particles_radial").type == "Integer"
    assert fmu3.var("at_rest").type == "Boolean" and fmu3.var("at_rest").causality == "output"
    assert fmu3.var("impact_speed").unit == "m/s" and float(fmu3.var("impact_speed").start) == 181.0
    assert float(fmu3.var("density").max) == 1e5
    out = {v.name for v in fmu3.outputs}
    ref = coarse_cli(tmp_path_factory)
    assert out == {k for k, v in ref.items() if not isinstance(v, dict)} - {
        "particles", "steps", "end_time", "wall_time_s", "outcome"}
    assert not names3 & {"shock_radius", "post_shock_density", "pre_shock_density_l1"}
    xml3 = (Path(fmu3.unzipdir) / "modelDescription.xml").read_text()
    xml2 = (Path(fmu2.unzipdir) / "modelDescription.xml").read_text()
    assert 'canGetAndSetFMUState="true"' in xml3 and 'canSerializeFMUState="true"' in xml3
    assert 'canGetAndSetFMUstate="true"' in xml2 and 'canSerializeFMUstate="true"' in xml2
    assert 'canNotUseMemoryManagementFunctions="true"' in xml2
    assert fmu3.md.guid == fmu2.md.guid


def test_defaults_equal_the_cli(fmu3, tmp_path_factory):
    """The one run at the default resolution (20 particles across the radius)."""
    ref = cli_run(tmp_path_factory)
    r = simulate_fmu(str(fmu3.path), output=["rod_length", "mushroom_radius", "at_rest"])
    assert r["rod_length"][-1] == ref["rod_length"]
    assert r["mushroom_radius"][-1] == ref["mushroom_radius"]
    assert r["at_rest"][-1] and not r["at_rest"][0]
    assert abs(ref["rod_length"] - 34.58e-3) < 0.01e-3  # VALIDATION.md, "Right by default", test 7
    # The run went on past the rest to stopTime (400 µs), the outputs held.
    assert_held_past_the_end(r, ref, 400e-6)


def assert_held_past_the_end(r, ref, stop):
    """`simulate_fmu`'s result `r` of a Taylor FMU reached `stop`, past the
    rod's rest; at_rest came at the communication point of the step that
    reached the CLI's moment of rest (within one communication step: a
    solver step is not shortened at a communication point) and the rod's
    length held its final value from there on."""
    t = r["time"]
    assert t[-1] == pytest.approx(stop, rel=1e-12)
    first = next(i for i, x in enumerate(r["at_rest"]) if x)
    assert abs(t[first] - ref["end_time"]) < t[first] - t[first - 1]
    assert t[first] < stop
    assert all(x for x in r["at_rest"][first:])
    assert all(x == ref["rod_length"] for x in r["rod_length"][first:])


def test_fmi2_equals_fmi3_equals_cli(fmu3, fmu2, tmp_path_factory):
    ref = coarse_cli(tmp_path_factory)
    names = [v.name for v in fmu3.outputs]
    r3 = simulate_fmu(str(fmu3.path), start_values={"particles_radial": COARSE}, output=names)
    r2 = simulate_fmu(str(fmu2.path), start_values={"particles_radial": COARSE}, output=names)
    for name in names:
        assert r3[name][-1] == r2[name][-1] == ref[name] or name == "at_rest", name
    assert r3["at_rest"][-1] and r2["at_rest"][-1]
    # Both run on past the rest to stopTime (400 µs), every step complete.
    for r in (r3, r2):
        assert_held_past_the_end(r, ref, 400e-6)
    assert list(r3["time"]) == list(r2["time"])
    # FMI 3 with early return allowed returns at the moment of rest, as the
    # CLI reports it, and steps on from there to stopTime.
    r3e = simulate_fmu(str(fmu3.path), start_values={"particles_radial": COARSE}, output=["rod_length"],
                       early_return_allowed=True)
    t = list(r3e["time"])
    assert t.count(ref["end_time"]) == 1 and ref["end_time"] not in r3["time"]
    assert r3e["rod_length"][t.index(ref["end_time"])] == ref["rod_length"]
    assert r3e["time"][-1] == r3["time"][-1] and len(t) == len(r3["time"]) + 1
    assert all(x == ref["rod_length"] for x in r3e["rod_length"][t.index(ref["end_time"]):])


def test_start_values_act_in_the_physical_direction(fmu3, tmp_path_factory):
    slow = run3(fmu3, {"particles_radial": COARSE, "impact_speed": 181.0})
    fast = run3(fmu3, {"particles_radial": COARSE, "impact_speed": 250.0})
    assert fast["rod_length"] < slow["rod_length"] - 1e-3
    assert fast["mushroom_radius"] > slow["mushroom_radius"] + 0.2e-3
    assert fast["max_plastic_strain"] > slow["max_plastic_strain"]
    strong = run3(fmu3, {"particles_radial": COARSE, "jc_a": 1.2e9})
    assert strong["rod_length"] > slow["rod_length"]
    assert_equal_to_cli(fast, coarse_cli(tmp_path_factory, "impact_speed=250"))


@pytest.mark.parametrize("which", ["fmu3", "fmu2"])
@pytest.mark.parametrize("step", [1e-7, 1e-6, 1e-5])
def test_any_communication_step(which, step, request, tmp_path_factory):
    m = request.getfixturevalue(which)
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values={"particles_radial": COARSE}, output=names,
                     output_interval=step, stop_time=1e-4)
    ref = coarse_cli(tmp_path_factory)
    assert_equal_to_cli({n: (bool(r[n][-1]) if n == "at_rest" else r[n][-1]) for n in names}, ref)
    assert len(r) >= int(ref["end_time"] / step)


def test_fixed_parameter_refused_after_initialization(fmu3, fmu2):
    for init in (init3, init2):
        m = fmu3 if init is init3 else fmu2
        s = init(m, {"particles_radial": COARSE})
        MESSAGES.clear()
        with pytest.raises(FMICallException) as e:
            set_params(s, m, {"impact_speed": 200.0})
        assert e.value.status == 3
        assert any("`impact_speed` is a fixed parameter and cannot be changed after initialization" in x
                   for x in messages("logStatusError")), MESSAGES
        s.freeInstance()


def test_bad_value_is_refused_with_its_name_value_and_range(fmu3, fmu2):
    for m, make in ((fmu3, slave3), (fmu2, slave2)):
        s = make(m)
        MESSAGES.clear()
        with pytest.raises(FMICallException):
            set_params(s, m, {"density": -5.0})
        assert "parameter `density` = -5 is out of range: allowed [100, 100000]" in messages("logStatusError")
        s.freeInstance()
    # A cross-check fails when initialization ends.
    s = slave3(fmu3)
    set_params(s, fmu3, {"initial_temperature": 1500.0})
    s.enterInitializationMode(startTime=0.0)
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        s.exitInitializationMode()
    assert any("initial_temperature = 1500 K must be below melt_temperature" in x for x in messages()), MESSAGES
    s.freeInstance()


def test_start_value_on_an_output_is_refused(fmu3, fmu2):
    for m in (fmu3, fmu2):
        with pytest.raises(Exception, match="could not be set: rod_length"):
            simulate_fmu(str(m.path), start_values={"rod_length": 0.01, "particles_radial": COARSE})
    s = slave3(fmu3)
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        s.setFloat64([fmu3.vr("rod_length")], [0.01])
    assert "fmi3SetFloat64: `rod_length` is an output and cannot be set" in messages("logStatusError")
    s.freeInstance()


def test_wrong_time_and_nonpositive_step_are_refused(fmu3, fmu2):
    cases = [(0.5e-6, 1e-6, "does not match the FMU's time"), (0.0, 0.0, "must be positive"),
             (0.0, -1e-6, "must be positive")]
    for current, step, text in cases:
        s = init3(fmu3, {"particles_radial": COARSE})
        MESSAGES.clear()
        with pytest.raises(FMICallException) as e:
            s.doStep(currentCommunicationPoint=current, communicationStepSize=step)
        assert e.value.status == 3
        assert any(text in x for x in messages("logStatusError")), MESSAGES
        # Error leads to Terminated: stepping is no longer allowed ...
        with pytest.raises(FMICallException):
            s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
        assert any("not allowed in state Terminated" in x for x in messages())
        # ... but outputs can be read and the instance freed.
        assert s.getFloat64([fmu3.vr("rod_length")])[0] == pytest.approx(0.03797)
        s.freeInstance()
    s = init2(fmu2, {"particles_radial": COARSE})
    with pytest.raises(FMICallException):
        s.doStep(currentCommunicationPoint=1e-6, communicationStepSize=1e-6)
    s.freeInstance()
    # A call out of sequence is refused too.
    s = slave3(fmu3)
    MESSAGES.clear()
    with pytest.raises(FMICallException):
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
    assert "fmi3DoStep: not allowed in state Instantiated" in messages("logStatusError")
    s.freeInstance()


@pytest.mark.parametrize("which", ["fmu3", "fmu2"])
def test_step_past_stop_time_is_an_error(which, request):
    """FMI 2.0 (fmi2SetupExperiment) and FMI 3.0 (fmi3EnterInitializationMode):
    with a stop time defined, a doStep that would end past it returns Error;
    one that ends on it up to rounding (1e-9 of |stopTime| + step) is fine."""
    m = request.getfixturevalue(which)

    def start(stop_time):
        if which == "fmu3":
            s = slave3(m)
            set_params(s, m, {"particles_radial": COARSE})
            s.enterInitializationMode(startTime=0.0, stopTime=stop_time)
        else:
            s = slave2(m)
            set_params(s, m, {"particles_radial": COARSE})
            s.setupExperiment(startTime=0.0, stopTime=stop_time)
            s.enterInitializationMode()
        s.exitInitializationMode()
        return s

    # Six steps of 0.3 us, summed as a host does, end one ulp past 1.8 us.
    s = start(1.8e-6)
    t, h = 0.0, 3e-7
    for _ in range(6):
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
    assert t > 1.8e-6
    # One step more ends past stopTime.
    MESSAGES.clear()
    with pytest.raises(FMICallException) as e:
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    assert e.value.status == 3
    fn = "fmi3DoStep" if which == "fmu3" else "fmi2DoStep"
    assert any(x.startswith(f"{fn}: the step would end at t = 0.0000021") and "past stopTime = 0.0000018 s" in x
               for x in messages("logStatusError")), MESSAGES
    # Error leads to Terminated.
    with pytest.raises(FMICallException):
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    assert any("not allowed in state Terminated" in x for x in messages("logStatusError")), MESSAGES
    s.freeInstance()
    # A single step just past stopTime (by 1e-6 of it) is refused too ...
    s = start(1.8e-6)
    with pytest.raises(FMICallException) as e:
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1.8e-6 * (1 + 1e-6))
    assert e.value.status == 3
    s.freeInstance()
    # ... and allowed when no stop time was given.
    s = start(None)
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1.8e-6 * (1 + 1e-6))
    s.freeInstance()


def test_two_interleaved_instances_equal_two_separate_runs(fmu3, tmp_path_factory):
    a = init3(fmu3, {"particles_radial": COARSE}, name="a")
    b = init3(fmu3, {"particles_radial": COARSE, "impact_speed": 250.0}, name="b")
    step, n, done = 1e-6, 0, {}
    rest = fmu3.vr("at_rest")
    while len(done) < 2:
        for name, s in (("a", a), ("b", b)):
            # Both step on, the one at rest too (its outputs hold).
            r = s.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
            assert not r[1]
            if name not in done and s.getBoolean([rest])[0]:
                done[name] = outputs(s, fmu3)
        n += 1
    assert outputs(a, fmu3) == done["a"] and outputs(b, fmu3) == done["b"]
    assert_equal_to_cli(done["a"], coarse_cli(tmp_path_factory))
    assert_equal_to_cli(done["b"], coarse_cli(tmp_path_factory, "impact_speed=250"))
    a.freeInstance()
    b.freeInstance()


def test_instances_run_in_parallel_threads(fmu3, tmp_path_factory):
    results = {}

    def work(speed):
        results[speed] = run3(fmu3, {"particles_radial": COARSE, "impact_speed": speed}, name=f"v{speed}")

    threads = [threading.Thread(target=work, args=(v,)) for v in (181.0, 250.0)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert_equal_to_cli(results[181.0], coarse_cli(tmp_path_factory))
    assert_equal_to_cli(results[250.0], coarse_cli(tmp_path_factory, "impact_speed=250"))


def _step_until_end(s, m, step=1e-6):
    return step_past_the_end(s, m, step)[1]


def test_reset_then_second_run_is_bit_identical(fmu3):
    s = init3(fmu3, {"particles_radial": COARSE, "impact_speed": 220.0})
    _step_until_end(s, fmu3)
    first = outputs(s, fmu3)
    s.terminate()
    s.reset()
    # Reset restores the default parameters.
    s.enterInitializationMode(startTime=0.0)
    assert s.getInt32([fmu3.vr("particles_radial")]) == [20]
    s.reset()
    set_params(s, fmu3, {"particles_radial": COARSE, "impact_speed": 220.0})
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    _step_until_end(s, fmu3)
    second = outputs(s, fmu3)
    assert first == second
    assert np.array([first[k] for k in first]).tobytes() == np.array([second[k] for k in second]).tobytes()
    s.freeInstance()


def test_fmu_state_rolls_back_a_step_exactly_fmi3(fmu3):
    s = init3(fmu3, {"particles_radial": COARSE})
    step = 1e-6
    for n in range(10):
        s.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
    state = s.getFMUState()
    s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    after = outputs(s, fmu3)
    s.doStep(currentCommunicationPoint=11 * step, communicationStepSize=step)
    assert outputs(s, fmu3) != after
    s.setFMUState(state)
    s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    assert outputs(s, fmu3) == after
    # Through bytes, into a second instance.
    data = s.serializeFMUState(state)
    assert len(data) > 1000
    t = slave3(fmu3, name="copy")
    restored = t.deserializeFMUState(data)
    t.setFMUState(restored)
    t.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    assert outputs(t, fmu3) == after
    # Rolling back also recovers from the end of the run.
    _step_until_end_from(t, fmu3, 11 * step)
    t.setFMUState(restored)
    t.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    assert outputs(t, fmu3) == after
    for x in (s, t):
        x.freeFMUState(state if x is s else restored)
        x.freeInstance()


def _step_until_end_from(s, m, t0, step=1e-6):
    step_past_the_end(s, m, step, t0=t0)


def test_fmu_state_rolls_back_a_step_exactly_fmi2(fmu2):
    s = init2(fmu2, {"particles_radial": COARSE})
    step = 1e-6
    for n in range(10):
        s.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
    state = s.getFMUstate()
    s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    after = outputs(s, fmu2)
    s.setFMUstate(state)
    s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    assert outputs(s, fmu2) == after
    data = s.serializeFMUstate(state)
    s.freeFMUstate(state)
    s.setFMUstate(s.deSerializeFMUstate(data))
    s.doStep(currentCommunicationPoint=10 * step, communicationStepSize=step)
    assert outputs(s, fmu2) == after
    s.freeInstance()


def _refused(m, data):
    """Deserializes `data` into a new FMI 3 instance; True when refused with
    Error (the instance is freed either way)."""
    t = slave3(m, name="forged")
    try:
        restored = t.deserializeFMUState(data)
    except FMICallException as e:
        assert e.status == 3, e
        t.freeInstance()
        return True
    t.freeFMUState(restored)
    t.freeInstance()
    return False


def test_cut_foreign_and_old_fmu_states_are_refused(fmu3):
    """The FMU state is postcard (the typed forgeries, a mass or a density
    edited, are refused in the Rust tests, which decode, edit and encode
    it): every cut, a byte added, another FMU's or an older build's header,
    and a version 1 (JSON) state are refused with Error."""
    s = init3(fmu3, {"particles_radial": COARSE})
    for n in range(3):
        s.doStep(currentCommunicationPoint=n * 1e-6, communicationStepSize=1e-6)
    state = s.getFMUState()
    data = bytes(s.serializeFMUState(state))
    magic_end = data.index(b"\n") + 1
    assert data[:magic_end] == b"TaylorImpact FMU state v2 postcard\n"
    token_end = data.index(b"\n", magic_end) + 1
    body = len(data) - token_end
    cuts = sorted({0, 5, magic_end, token_end - 1, token_end, len(data) - 1}
                  | {token_end + body * k // 16 for k in range(16)})
    for cut in cuts:
        assert _refused(fmu3, data[:cut]), cut
    assert _refused(fmu3, data + b"\0")
    assert _refused(fmu3, b"NohImpact" + data[len(b"TaylorImpact"):])
    other_build = bytearray(data)
    other_build[token_end - 3] ^= 1
    assert _refused(fmu3, bytes(other_build))
    v1 = b"TaylorImpact FMU state v1\n" + data[magic_end:token_end] + b'{"state": 4}'
    assert _refused(fmu3, v1)
    # The unedited bytes still load.
    assert not _refused(fmu3, data)
    s.freeFMUState(state)
    s.freeInstance()


def test_fmu_states_with_a_byte_changed_are_refused_or_run_finite(fmu3):
    """A byte changed anywhere in the body: the state is refused with Error,
    or it is one the checks cannot tell from a run's, and then it steps to
    finite outputs or stops with Error (never NaN, never Fatal)."""
    s = init3(fmu3, {"particles_radial": COARSE})
    for n in range(3):
        s.doStep(currentCommunicationPoint=n * 1e-6, communicationStepSize=1e-6)
    state = s.getFMUState()
    data = bytes(s.serializeFMUState(state))
    token_end = data.index(b"\n", data.index(b"\n") + 1) + 1
    rng = np.random.default_rng(19)
    refused = accepted = 0
    for at in rng.integers(token_end, len(data), 60):
        for flip in (0x01, 0x80, 0xFF):
            forged = bytearray(data)
            forged[at] ^= flip
            t = slave3(fmu3, name="flipped")
            try:
                restored = t.deserializeFMUState(bytes(forged))
            except FMICallException as e:
                assert e.status == 3, e
                refused += 1
                t.freeInstance()
                continue
            accepted += 1
            t.setFMUState(restored)
            try:
                t.doStep(currentCommunicationPoint=3e-6, communicationStepSize=1e-6)
            except FMICallException as e:
                assert e.status == 3, e
            else:
                values = outputs(t, fmu3)
                assert all(np.isfinite(float(v)) for v in values.values()), (at, flip, values)
            t.freeFMUState(restored)
            t.freeInstance()
    assert refused > 0 and refused + accepted == 180
    s.freeFMUState(state)
    s.freeInstance()


def test_fmi2_steps_past_the_rest_complete_and_hold(fmu2, tmp_path_factory):
    """FMI 2 (issue 65): the step into the rest and every step after it
    answer fmi2OK (no fmi2Discard, which stopped libcosim), the status is
    OK and not Terminated, the last successful time the end of the step,
    and the outputs hold the CLI's final values; the host's stopTime is
    reached."""
    ref = coarse_cli(tmp_path_factory)
    s = slave2(fmu2)
    set_params(s, fmu2, {"particles_radial": COARSE})
    stop = 100e-6
    s.setupExperiment(startTime=0.0, stopTime=stop)
    s.enterInitializationMode()
    s.exitInitializationMode()
    out, n = step_past_the_end(s, fmu2, 1e-6, end=ref["end_time"])
    assert_equal_to_cli(out, ref)
    assert n == math.ceil(ref["end_time"] / 1e-6) + 1
    while n < 100:
        s.doStep(currentCommunicationPoint=n * 1e-6, communicationStepSize=1e-6)
        n += 1
        assert outputs(s, fmu2) == out
    assert s.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(stop, rel=1e-12)
    assert not s.getBooleanStatus(fmi2Terminated)
    s.terminate()
    s.freeInstance()


def test_logging_respects_logging_on(fmu3, fmu2):
    MESSAGES.clear()
    run3(fmu3, {"particles_radial": COARSE}, logging_on=False)
    assert MESSAGES == []
    MESSAGES.clear()
    run3(fmu3, {"particles_radial": COARSE}, logging_on=True)
    assert any(m.startswith("t = ") for m in messages("logProgress"))
    assert any("the rod is at rest" in m for m in messages("logEvents"))
    # Only the chosen categories.
    s = init3(fmu3, {"particles_radial": COARSE})
    s.setDebugLogging(True, ["logEvents"])
    MESSAGES.clear()
    _step_until_end(s, fmu3)
    assert messages("logProgress") == [] and len(messages("logEvents")) == 1
    with pytest.raises(FMICallException):
        s.setDebugLogging(True, ["noSuchCategory"])
    assert any("unknown log category `noSuchCategory`" in m for m in messages("logStatusError"))
    s.freeInstance()
    # FMI 2: the same through the printf-style logger ('%' arrives intact).
    MESSAGES.clear()
    s = init2(fmu2, {"particles_radial": COARSE}, logging_on=True)
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-6)
    assert any(m.startswith("t = 1.0") for m in messages("logProgress")), MESSAGES
    s.freeInstance()


@pytest.mark.parametrize("which", ["fmu3", "fmu2"])
def test_thousand_load_instantiate_free_unload_cycles(which, request):
    m = request.getfixturevalue(which)
    for k in range(1000):
        if which == "fmu3":
            s = FMU3Slave(guid=m.md.guid, unzipDirectory=m.unzipdir,
                          modelIdentifier=m.md.coSimulation.modelIdentifier, instanceName=f"c{k}")
            s.instantiate(logMessage=_log3)
        else:
            s = FMU2Slave(guid=m.md.guid, unzipDirectory=m.unzipdir,
                          modelIdentifier=m.md.coSimulation.modelIdentifier, instanceName=f"c{k}")
            s.instantiate(callbacks=CALLBACKS2)
        s.freeInstance()
        s.freeLibrary()
    # Still usable afterwards.
    if which == "fmu3":
        assert run3(m, {"particles_radial": 4})["at_rest"] is True
    else:
        s = init2(m, {"particles_radial": 4})
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=2e-6)
        assert 0.0370 < outputs(s, m)["rod_length"] < 0.03797
        s.freeInstance()


def test_wrong_token_is_refused(fmu3):
    s = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=fmu3.unzipdir,
                  modelIdentifier="TaylorImpact", instanceName="x")
    MESSAGES.clear()
    with pytest.raises(Exception):
        s.instantiate(logMessage=_log3)
    # The library serves every FMU of the registry: an unknown token is
    # refused with the tokens it knows, this FMU's among them.
    errors = messages("logStatusError")
    assert any("is not one of this library's FMUs" in m and fmu3.md.guid in m
               and "TaylorImpact" in m for m in errors), errors
