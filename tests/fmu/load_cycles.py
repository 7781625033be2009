"""Load/unload cycles of every FMU with flat memory (issue 48), part of the
long fuzz run (scripts/fuzz.sh), not of the test command.

For every FMU that `cargo xtask fmu` built (FMI 3.0 `ID.fmu` and FMI 2.0
`ID_fmi2.fmu`), CYCLES times in one process: load the shared library,
instantiate, set a parameter (the resolution, to the smallest value with
which the FMU initializes, so that the model is cheap to build), enter and leave initialization (the model is
built), take one small step, free the instance and unload the library.

The resident set size (VmRSS of /proc/self/status) is read after WARMUP
cycles (allocator arenas, caches and fmpy's own objects settle) and after the
last cycle, and so is the number of threads. Fails when the RSS grew by more
than THRESHOLD_MIB (4 MiB by default), or the number of threads grew, on any
FMU. Why 4 MiB: a model that is not freed costs more than 10 KiB per cycle
even at the smallest resolution (its particle or node arrays, neighbour
lists and history), so it would grow the RSS by more than 9 MiB over the 950
measured cycles, and a library mapped anew without being unmapped costs
megabytes per cycle; 4 MiB is 4.3 KiB per cycle. The growth measured on
every FMU ranges from -0.5 to +1.04 MiB (glibc's allocator between two
readings; 2026-11-27 and, all seven FMUs, 2026-11-29), so the bound has a
margin of almost 4 over that noise.

Reloading from the same unzip directory reuses the library: once a model
has run, glibc keeps the library loaded after freeLibrary (its worker
threads hold thread-local destructors), and each distinct unzip directory
leaves one such copy (about 2.5 MiB and one thread pool); the RSS and thread
steps between FMUs in the table are that, not growth over cycles.

Usage: python tests/fmu/load_cycles.py [--dir DIR] [--cycles N] [--warmup N]
       [--threshold-mib X] [--no-step] [FMU names...]
DIR defaults to $CARGO_TARGET_DIR/fmu, else target/fmu. Needs fmpy (the
virtual environment that tests/fmu/run.sh creates).
"""

import argparse
import gc
import os
import shutil
import sys
import time
from pathlib import Path

import fmpy
from fmpy import extract, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave

ROOT = Path(__file__).resolve().parents[2]


def _log3(env, status, category, message):
    pass


def _log2(env, instance_name, status, category, message):
    pass


CALLBACKS2 = fmi2CallbackFunctions()
CALLBACKS2.logger = fmi2CallbackLoggerTYPE(_log2)
CALLBACKS2.allocateMemory = fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
CALLBACKS2.freeMemory = fmi2CallbackFreeMemoryTYPE(fmpy.free)


def status(key):
    """The first number of the line `key:` of /proc/self/status."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"no {key} in /proc/self/status")


def rss_kib():
    """The process's resident set size, KiB."""
    return status("VmRSS")


def threads():
    """The process's number of threads."""
    return status("Threads")


def resolution_candidates(md):
    """The parameter to set in each cycle and the values to try for it, the
    cheapest first: the resolution `particles_radial` from its smallest
    allowed value up to its start value, else the first parameter at its
    start value. (Not the first integer parameter: FMI 2 declares an
    enumeration an Integer too, and BallisticImpact's first, plate_ceramic
    (since 2026-11-28), left its FMI 2 cycles at the default 6 nodes across
    until 2026-11-29.)"""
    params = [v for v in md.modelVariables if v.causality == "parameter"]
    for v in params:
        if v.name == "particles_radial" and v.type in ("Int32", "Integer") and v.min is not None:
            lo, start = int(v.min), int(v.start)
            return v, list(range(lo, start + 1))
    v = params[0]
    return v, [int(v.start) if v.type in ("Int32", "Integer") else float(v.start)]


class Fmu:
    def __init__(self, path):
        self.path = path
        self.md = read_model_description(str(path))
        self.fmi3 = self.md.fmiVersion.startswith("3")
        self.unzipdir = extract(str(path))
        self.param, candidates = resolution_candidates(self.md)
        self.value = candidates[-1]

    def choose(self, step):
        """Sets `value` to the cheapest candidate with which a cycle runs
        without error (some scenes refuse their smallest resolution with the
        other parameters at their defaults)."""
        _, candidates = resolution_candidates(self.md)
        for v in candidates:
            self.value = v
            try:
                self.cycle(-1, step)
                return
            except FMICallException:
                continue
        self.cycle(-1, step)  # raises with the start value

    def cycle(self, k, step):
        """One load/unload cycle; the instance and the library are freed
        even when a call fails."""
        md, ident = self.md, self.md.coSimulation.modelIdentifier
        vr = [self.param.valueReference]
        integer = self.param.type in ("Int32", "Integer")
        Slave = FMU3Slave if self.fmi3 else FMU2Slave
        s = Slave(guid=md.guid, unzipDirectory=self.unzipdir, modelIdentifier=ident,
                  instanceName=f"c{k}")
        try:
            if self.fmi3:
                s.instantiate(logMessage=_log3)
            else:
                s.instantiate(callbacks=CALLBACKS2)
            try:
                if self.fmi3:
                    (s.setInt32 if integer else s.setFloat64)(vr, [self.value])
                    if step:
                        s.enterInitializationMode(startTime=0.0)
                else:
                    (s.setInteger if integer else s.setReal)(vr, [self.value])
                    if step:
                        s.setupExperiment(startTime=0.0)
                        s.enterInitializationMode()
                if step:
                    s.exitInitializationMode()
                    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-7)
                    s.terminate()
            finally:
                s.freeInstance()
        finally:
            s.freeLibrary()

    def close(self):
        shutil.rmtree(self.unzipdir, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default_dir = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "fmu"
    ap.add_argument("--dir", type=Path, default=default_dir)
    ap.add_argument("--cycles", type=int, default=1000)
    ap.add_argument("--warmup", type=int, default=50)
    ap.add_argument("--threshold-mib", type=float, default=4.0)
    ap.add_argument("--no-step", action="store_true",
                    help="only instantiate and set a parameter (no initialization, no step)")
    ap.add_argument("names", nargs="*", help="FMU file names (default: every *.fmu in DIR)")
    a = ap.parse_args()
    if a.warmup >= a.cycles:
        ap.error("--warmup must be below --cycles")

    paths = [a.dir / n for n in a.names] if a.names else sorted(a.dir.glob("*.fmu"))
    if not paths:
        sys.exit(f"no FMU in {a.dir}: run `cargo xtask fmu` first")
    step = not a.no_step
    print(f"{len(paths)} FMUs in {a.dir}: {a.cycles} load/unload cycles each "
          f"({'instantiate, set, initialize, one step' if step else 'instantiate, set'}, "
          f"free instance, free library); RSS after {a.warmup} and after {a.cycles}, "
          f"allowed growth {a.threshold_mib} MiB", flush=True)
    print(f"{'FMU':41} {'FMI':>3} {'set':>20} {'cycles':>6} {'RSS@warmup':>10} {'RSS@end':>9} "
          f"{'growth':>9} {'threads':>7} {'time':>7}")
    failed = []
    t_all = time.perf_counter()
    for path in paths:
        fmu = Fmu(path)
        t0 = time.perf_counter()
        try:
            fmu.choose(step)
            for k in range(a.warmup):
                fmu.cycle(k, step)
            gc.collect()
            before, threads_before = rss_kib(), threads()
            for k in range(a.warmup, a.cycles):
                fmu.cycle(k, step)
            gc.collect()
            after, threads_after = rss_kib(), threads()
        finally:
            fmu.close()
        dt = time.perf_counter() - t0
        grew = after - before
        ok = grew <= a.threshold_mib * 1024 and threads_after <= threads_before
        if not ok:
            failed.append(path.name)
        setting = f"{fmu.param.name}={fmu.value}"
        print(f"{path.name:41} {fmu.md.fmiVersion[0]:>3} {setting:>20} {a.cycles:>6} "
              f"{before / 1024:>7.1f}MiB {after / 1024:>6.1f}MiB {grew / 1024:>+6.2f}MiB "
              f"{threads_before:>3}->{threads_after:<3} {dt:>6.1f}s{'' if ok else '  FAIL'}",
              flush=True)
    print(f"total {time.perf_counter() - t_all:.1f} s, final RSS {rss_kib() / 1024:.1f} MiB")
    if failed:
        sys.exit(f"RSS grew by more than {a.threshold_mib} MiB, or threads were left, over "
                 "load/unload cycles: " + ", ".join(failed))


if __name__ == "__main__":
    main()
