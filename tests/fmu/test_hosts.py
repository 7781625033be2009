"""Every FMU through three FMI hosts from PyPI, past its scene's end to the
host's stop time (issue 65, item 8): fmpy (FMI 3 and FMI 2), ecos
(`ecospy`; FMI 3 and FMI 2) and libcosim, the co-simulation engine of the
Open Simulation Platform (`libcosimpy`; FMI 2 only: libcosimpy 0.0.6
crashes loading an FMI 3 FMU, before it loads the FMU's library).
Each run must reach the host's stop time, and the outputs the host holds
there must be the command line's final values, bit for bit.

libcosim stopped with "Step not complete" in the step where the rod came
to rest while the FMU answered that step with fmi2Discard; an FMU whose
scene has ended now completes every step and holds its outputs
(docs/guide/fmu.md, "After the scene's end").

Every run is cheap: coarse lattices, short scenes. TaylorImpact runs to
rest at 200 m/s, 4 particles across (rest at 42.1 us; the case libcosim
failed on, at the default resolution), the other six to a short end_time. The scene ends inside a
communication step, not on one, and the host goes on for a few steps past
it."""

import math

import pytest
from fmpy import simulate_fmu

from conftest import cli_json, model

FMUS = ["TaylorImpact", "TaylorImpactBilinear", "TaylorImpactMieGruneisen", "TaylorImpactBilinearMieGruneisen",
        "Taylor3dImpact", "BallisticImpact", "PlateImpact"]

# identifier: (the command line's scene arguments, the parameters, the
# communication step, the host's stop time). The stop time lies a few
# steps past the scene's end; end_time is not a multiple of the step.
CASES = {
    "TaylorImpact": ([], {"particles_radial": 4, "impact_speed": 200.0}, 1e-6, 60e-6),
    "TaylorImpactBilinear": (["--strength", "bilinear", "--eos", "linear"],
                             {"particles_radial": 4, "end_time": 4.5e-6}, 1e-6, 8e-6),
    "TaylorImpactMieGruneisen": (["--strength", "johnson_cook", "--eos", "mie_gruneisen"],
                                 {"particles_radial": 4, "end_time": 4.5e-6}, 1e-6, 8e-6),
    "TaylorImpactBilinearMieGruneisen": (["--strength", "bilinear", "--eos", "mie_gruneisen"],
                                         {"particles_radial": 4, "end_time": 4.5e-6}, 1e-6, 8e-6),
    "Taylor3dImpact": (["taylor3d"], {"particles_radial": 3, "end_time": 2.5e-6}, 1e-6, 6e-6),
    "BallisticImpact": (["penetration"], {"particles_radial": 3, "plate_diameter": 0.02, "end_time": 1.5e-6},
                        1e-6, 5e-6),
    "PlateImpact": (["plate_impact"], {"cell": 4e-5, "end_time": 1.25e-6}, 5e-7, 3e-6),
}


def reference(identifier, tmp_path_factory):
    """The command line's final values for the case of `identifier`; it
    checks that the host's stop time lies past the scene's end."""
    scene, params, step, stop = CASES[identifier]
    sets = [a for name, value in params.items() for a in ("--set", f"{name}={value!r}")]
    ref = cli_json(tmp_path_factory, *scene, *sets)
    assert ref["end_time"] + 2 * step < stop, (identifier, ref["end_time"])
    if identifier == "TaylorImpact":
        assert ref["at_rest"] is True
    return ref


def outputs(m):
    """The FMU's outputs: (name, value reference, FMI type)."""
    return [(v.name, v.valueReference, v.type) for v in m.outputs]


def assert_final(values, ref, m):
    """`values` (name: value read by the host) are the CLI's `ref`, bit for
    bit; booleans as booleans."""
    names = [n for n, _, _ in outputs(m)]
    assert sorted(values) == sorted(names)
    for name in names:
        value = values[name]
        if isinstance(ref[name], bool):
            assert bool(value) == ref[name], name
        else:
            assert value == ref[name], f"{name}: host {value!r} CLI {ref[name]!r}"


def ints(m, params):
    """Which parameters are integers or enumerations in the FMU `m`."""
    return {n for n in params if m.var(n).type in ("Int32", "Integer", "Enumeration")}


# ------------------------------------------------------------------ fmpy
@pytest.mark.parametrize("suffix", ["", "_fmi2"])
@pytest.mark.parametrize("identifier", FMUS)
def test_fmpy_runs_past_the_scenes_end(identifier, suffix, tmp_path_factory):
    m = model(identifier, suffix)
    _, params, step, stop = CASES[identifier]
    ref = reference(identifier, tmp_path_factory)
    names = [n for n, _, _ in outputs(m)]
    r = simulate_fmu(str(m.path), start_values=params, output=names, stop_time=stop, output_interval=step)
    # To the stop time, every step: not stopped at the scene's end.
    assert math.isclose(r["time"][-1], stop, rel_tol=1e-9)
    assert len(r) == round(stop / step) + 1
    assert_final({n: r[n][-1] for n in names}, ref, m)
    # The outputs held from the scene's end on.
    past = [i for i, t in enumerate(r["time"]) if t > ref["end_time"] + 1e-12]
    assert len(past) >= 2
    for name in names:
        assert all(r[name][i] == r[name][-1] for i in past), name


# ------------------------------------------------------------------ ecos
@pytest.mark.parametrize("suffix", ["", "_fmi2"])
@pytest.mark.parametrize("identifier", FMUS)
def test_ecos_runs_past_the_scenes_end(identifier, suffix, tmp_path_factory):
    import ecospy  # needs libtbb12 (Debian's package; scripts/test.sh installs it)

    m = model(identifier, suffix)
    _, params, step, stop = CASES[identifier]
    ref = reference(identifier, tmp_path_factory)
    integers = ints(m, params)
    structure = ecospy.EcosSimulationStructure()
    structure.add_model("fmu", str(m.path))
    structure.add_parameter_set("initial", {f"fmu::{n}": (int(v) if n in integers else float(v))
                                            for n, v in params.items()})
    with ecospy.EcosSimulation(structure=structure, step_size=step) as sim:
        assert sim.init(parameter_set="initial")
        n = round(stop / step)
        t = sim.step(n)
        assert math.isclose(t, stop, rel_tol=1e-9) and math.isclose(sim.get_time(), stop, rel_tol=1e-9), t
        values = {}
        for name, _, ty in outputs(m):
            get = sim.get_bool if ty == "Boolean" else sim.get_real
            values[name] = get(f"fmu::{name}")
        sim.terminate()
    assert_final(values, ref, m)


# -------------------------------------------------------------- libcosim
@pytest.mark.parametrize("identifier", FMUS)
def test_libcosim_runs_past_the_scenes_end(identifier, tmp_path_factory):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    m = model(identifier, "_fmi2")
    _, params, step, stop = CASES[identifier]
    ref = reference(identifier, tmp_path_factory)
    integers = ints(m, params)
    ns = 1_000_000_000
    execution = CosimExecution.from_step_size(round(step * ns))
    index = execution.add_local_slave(CosimLocalSlave(fmu_path=str(m.path), instance_name="fmu"))
    for name, value in params.items():
        vr = m.vr(name)
        if name in integers:
            assert execution.integer_initial_value(index, vr, int(value))
        else:
            assert execution.real_initial_value(index, vr, float(value))
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer)
    assert execution.simulate_until(round(stop * ns)), "libcosim stopped before the stop time"
    assert execution.status().current_time == round(stop * ns)
    values = {}
    for name, vr, ty in outputs(m):
        read = observer.last_boolean_values if ty == "Boolean" else observer.last_real_values
        values[name] = read(index, [vr])[0]
    assert_final(values, ref, m)
