#!/usr/bin/env python3
"""The Lambert-Jonas ballistic-limit fit, as examples/ballistic_limit.py and
the FMU tests use it: the module of the Python package,
python/meshless_impact/lambert_jonas.py (one fit for the package's
`ballistic_limit` and the FMU sweep), loaded from the checkout so that it
runs without the package installed (numpy is all it needs).

    python examples/lambert_jonas.py shots.csv     # columns V_mps, Vr_mps
"""

import importlib.util
import sys
from pathlib import Path

_path = Path(__file__).resolve().parents[1] / "python" / "meshless_impact" / "lambert_jonas.py"
_spec = importlib.util.spec_from_file_location("_lambert_jonas", _path)
_module = importlib.util.module_from_spec(_spec)
# dataclasses looks the module up by name while it is loaded.
sys.modules[_spec.name] = _module
_spec.loader.exec_module(_module)

Fit = _module.Fit
fit = _module.fit
main = _module.main

if __name__ == "__main__":
    sys.exit(main(sys.argv))
