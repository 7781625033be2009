#!/usr/bin/env python3
"""Kill at random: the guide's check of checkpoints and restart
(docs/guide/checkpoints.md).

The penetration case (quarter model, 4 nodes across, to 20 us: about 2 s
on two cores) runs once uninterrupted, with its JSON, CSV and VTK outputs.
Then the same run, with a checkpoint every 10 steps, is killed with SIGKILL
at 20 random moments (each 0.05 to 0.35 s after its start, a fixed seed;
each kill must find the run still going) and restarted with `--restart`
each time; half way, a restart is sent SIGTERM (it must write its
checkpoint and its outputs so far, and exit 75). Then it runs to its end. After every kill,
every file in the output folder is checked whole: the checkpoint by its
trailer and a CRC-32 computed here (Python's zlib, an oracle independent
of the program's), the JSON and the collection by their parsers, the CSV by
its rows, each snapshot by the XML parser. At the end the results, the
history and every snapshot must be the uninterrupted run's, byte for byte
(the wall time aside).

    scripts/kill_restart.py [BINARY]   (default target/release/meshless-impact)

Exit status 0 when every check holds; it prints one line per kill.
"""

import csv
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
import zlib

BIN = sys.argv[1] if len(sys.argv) > 1 else "target/release/meshless-impact"
CASE = ["run", "penetration", "-q", "--set", "symmetry=1", "--set", "particles_radial=4"]
TIMES = "5e-6,10e-6,15e-6"
KILLS = 20
TRAILER = re.compile(rb"\nend crc32=([0-9a-f]{8}) bytes=([0-9]{20})\n\Z")


def outputs(d):
    return ["--json", f"{d}/out.json", "--csv", f"{d}/hist.csv",
            "--vtk-dir", f"{d}/vtk", "--vtk-times", TIMES]


def check_whole(d):
    """Every file there is whole; returns the checkpoint's length or None."""
    for name in os.listdir(d):
        path = os.path.join(d, name)
        if name.endswith(".partial"):
            continue  # a write the kill stopped: never read as a result
        if name == "out.json":
            json.loads(open(path).read())
        elif name == "hist.csv":
            rows = list(csv.reader(open(path, newline="")))
            assert rows and all(len(r) == len(rows[0]) for r in rows), path
    vtk = os.path.join(d, "vtk")
    if os.path.isdir(vtk):
        for name in os.listdir(vtk):
            if name.endswith((".vtu", ".pvd")):
                ET.parse(os.path.join(vtk, name))
    ckpt = os.path.join(d, "run.ckpt")
    if not os.path.exists(ckpt):
        return None
    data = open(ckpt, "rb").read()
    m = TRAILER.search(data)
    assert m, f"{ckpt}: no trailer"
    content = data[: m.start()]
    assert int(m.group(2)) == len(content), f"{ckpt}: length"
    assert zlib.crc32(content) == int(m.group(1), 16), f"{ckpt}: CRC-32"
    assert content.startswith(b"meshless-impact checkpoint 1\n"), ckpt
    return len(data)


def results(d):
    v = json.loads(open(f"{d}/out.json").read())
    v.pop("wall_time_s")
    return v


def main():
    rng = random.Random(71)
    root = tempfile.mkdtemp(prefix="mi-kill-")
    whole, killed = f"{root}/whole", f"{root}/killed"
    os.makedirs(whole)
    os.makedirs(killed)
    t0 = time.time()
    subprocess.run([BIN, *CASE, *outputs(whole)], check=True)
    print(f"uninterrupted run: {time.time() - t0:.2f} s")
    ckpt = f"{killed}/run.ckpt"
    first = [BIN, *CASE, *outputs(killed), "--checkpoint", ckpt, "--checkpoint-steps", "10"]
    for k in range(KILLS):
        cmd = [BIN, "run", "-q", "--restart", ckpt] if os.path.exists(ckpt) else first
        p = subprocess.Popen(cmd)
        delay = rng.uniform(0.05, 0.35)
        time.sleep(delay)
        assert p.poll() is None, f"kill {k + 1}: the run ended before it (a faster machine?)"
        p.send_signal(signal.SIGKILL)
        p.wait()
        size = check_whole(killed)
        print(f"kill {k + 1:2d} after {delay:.2f} s: every file whole; checkpoint "
              f"{'none yet' if size is None else f'{size} bytes'}")
        if k + 1 == KILLS // 2:
            p = subprocess.Popen([BIN, "run", "-q", "--restart", ckpt], stderr=subprocess.PIPE,
                                 text=True)
            time.sleep(0.2)
            p.send_signal(signal.SIGTERM)
            err = p.communicate()[1]
            assert p.returncode == 75, (p.returncode, err)
            assert "interrupted by SIGTERM" in err, err
            check_whole(killed)
            assert results(killed)["outcome"] == "interrupted"
            print("SIGTERM: exit 75, the checkpoint and the outputs so far written")
    subprocess.run([BIN, "run", "-q", "--restart", ckpt], check=True)
    assert results(killed) == results(whole), "the results differ"
    assert open(f"{killed}/hist.csv", "rb").read() == open(f"{whole}/hist.csv", "rb").read()
    names = sorted(os.listdir(f"{whole}/vtk"))
    assert names == sorted(n for n in os.listdir(f"{killed}/vtk") if not n.endswith(".partial"))
    for n in names:
        assert open(f"{killed}/vtk/{n}", "rb").read() == open(f"{whole}/vtk/{n}", "rb").read(), n
    print(f"after {KILLS} kills and a SIGTERM: the results, the history and "
          f"{len(names)} snapshot files are the uninterrupted run's, byte for byte")
    shutil.rmtree(root)


if __name__ == "__main__":
    main()
