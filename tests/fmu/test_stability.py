"""Stiff, extreme and invalid cases of the stability matrix (docs/report)
through the FMUs: stiff material with a 10 µs communication step, runs that
stop with a named error, and every invalid input refused with its name."""

import math

import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from conftest import COARSE, cli_run
from test_fmu import (MESSAGES, assert_initialization_refused, assert_set_refused, init2, init3, messages, outputs,
                      run3, slave2, slave3)

BULK = 169.1e9


@pytest.mark.parametrize("factor", [10, 100])
def test_stiff_material_with_a_10us_communication_step_equals_the_cli(fmu3, tmp_path_factory, factor):
    """bulk_modulus x10 and x100: the internal step falls with the wave speed,
    the host steps 10 µs at a time, and the run ends at rest with finite
    outputs equal to the command line's bit for bit."""
    k = BULK * factor
    out = run3(fmu3, {"particles_radial": COARSE, "bulk_modulus": k}, step=10e-6)
    ref = cli_run(tmp_path_factory, f"particles_radial={COARSE}", f"bulk_modulus={k!r}")
    assert out["at_rest"] is True
    for name, value in out.items():
        if name != "at_rest":
            assert math.isfinite(value), name
            assert value == ref[name], f"{name}: FMU {value!r} CLI {ref[name]!r}"
    assert 0.0 <= out["energy_error"] < 0.05


@pytest.mark.parametrize("params, needle", [
    ({"smoothing_ratio": 1.0}, "singular MSPH moment matrix"),
    ({"smoothing_coefficient": 0.0}, "exceeds the bound 0.1"),
    ({"impact_speed": 800.0}, "particle spacing collapsed"),
])
def test_a_solver_stop_is_an_error_with_its_name(fmu3, fmu2, params, needle):
    """A run that leaves the solver's domain stops with Error and the named
    message in the host's log; the outputs stay finite and readable. With
    the paper's scheme (`scheme` = 1): the default, large_strain, brings the
    rod at 800 m/s to rest."""
    params = {"particles_radial": COARSE, "scheme": 1, **params}
    for m, init in ((fmu3, init3), (fmu2, init2)):
        s = init(m, params)
        MESSAGES.clear()
        with pytest.raises(FMICallException) as e:
            t = 0.0
            for _ in range(100):
                s.doStep(currentCommunicationPoint=t, communicationStepSize=1e-6)
                t += 1e-6
        assert e.value.status == 3
        assert any(needle in x for x in messages("logStatusError")), MESSAGES
        assert all(math.isfinite(v) for k, v in outputs(s, m).items() if k != "at_rest")
        s.freeInstance()


@pytest.mark.parametrize("name, value, needle", [
    ("density", -7830.0, "parameter `density` = -7830 is out of range"),
    ("initial_diameter", 0.0, "parameter `initial_diameter` = 0 is out of range"),
    ("impact_speed", float("nan"), "parameter `impact_speed` = NaN is out of range"),
    ("impact_speed", float("inf"), "parameter `impact_speed` = inf is out of range"),
    ("particles_radial", 0, "parameter `particles_radial` = 0 is out of range"),
])
def test_invalid_value_is_refused_with_its_name(fmu3, fmu2, name, value, needle):
    for m, make in ((fmu3, slave3), (fmu2, slave2)):
        assert_set_refused(m, make, {name: value}, needle)


def test_melt_at_room_temperature_is_refused_at_initialization(fmu3, fmu2):
    for m, make in ((fmu3, slave3), (fmu2, slave2)):
        assert_initialization_refused(m, make, {"melt_temperature": 293.0}, "must exceed room_temperature")


def test_unknown_parameter_name_is_refused(fmu3, fmu2):
    for m in (fmu3, fmu2):
        with pytest.raises(Exception, match="could not be set: impact_sped"):
            simulate_fmu(str(m.path), start_values={"impact_sped": 200.0, "particles_radial": COARSE})
