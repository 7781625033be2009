"""The numerical scheme by name through the FMUs (README, "Schemes"): in
FMI 3 the `scheme` parameter is an Enumeration whose items are the scheme
names, in FMI 2 an Integer whose levels its description lists; either way
the scheme chosen by its value, with or without a knob set by hand, gives
the bits of the CLI's `--scheme NAME`."""

import pytest
from fmpy import simulate_fmu

from conftest import COARSE, assert_simulated_equal_to_cli, cli_json, model

FMUS = [
    ("TaylorImpact", "taylor", ["large_strain", "paper"], COARSE),
    ("Taylor3dImpact", "taylor3d", ["large_strain", "paper"], 4),
    ("BallisticImpact", "penetration", ["ballistic", "paper"], None),
]


@pytest.mark.parametrize("identifier,scene,levels,nodes", FMUS)
def test_the_scheme_is_an_enumeration_in_fmi3_and_an_integer_in_fmi2(identifier, scene, levels, nodes):
    m3, m2 = model(identifier), model(identifier, "_fmi2")
    v3, v2 = m3.var("scheme"), m2.var("scheme")
    assert v3.type == "Enumeration" and v2.type == "Integer"
    assert v3.causality == v2.causality == "parameter"
    assert int(v3.start) == int(v2.start) == 0
    items = [item.name for item in v3.declaredType.items]
    assert items == levels
    assert [int(item.value) for item in v3.declaredType.items] == list(range(len(levels)))
    for k, name in enumerate(levels):
        assert f"{k} = {name}" in v2.description


@pytest.mark.parametrize("suffix", ["", "_fmi2"])
@pytest.mark.parametrize(
    "identifier,scene,nodes,knob",
    [("TaylorImpact", "taylor", COARSE, None), ("TaylorImpact", "taylor", COARSE, ("shifting", 0.05)),
     ("Taylor3dImpact", "taylor3d", 4, None)],
)
def test_the_paper_scheme_by_its_value_equals_the_cli(identifier, scene, nodes, knob, suffix, tmp_path_factory):
    m = model(identifier, suffix)
    start = {"particles_radial": nodes, "end_time": 10e-6, "scheme": 1}
    args = [scene, "--scheme", "paper", "--set", f"particles_radial={nodes}", "--set", "end_time=1e-5"]
    if knob:
        start[knob[0]] = knob[1]
        args += ["--set", f"{knob[0]}={knob[1]}"]
    ref = cli_json(tmp_path_factory, *args)
    default = cli_json(tmp_path_factory, scene, "--set", f"particles_radial={nodes}", "--set", "end_time=1e-5")
    assert ref["rod_length"] != default["rod_length"]
    names = [v.name for v in m.outputs]
    r = simulate_fmu(str(m.path), start_values=start, output=names, stop_time=10e-6)
    assert_simulated_equal_to_cli(r, ref, names)
