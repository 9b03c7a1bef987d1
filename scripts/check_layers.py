#!/usr/bin/python3
"""Layer check of the source tree (standard library only).

Scans every `#include "..."` in host_sim/, firmware/ and hal/ and checks it against the
layer table below (docs/architecture.md, "Host layers", shows the same table):

  * host_sim/: each folder sits in one layer; a folder may include folders of LOWER layers
    only (never a folder of its own layer, never a higher one). A folder missing from the
    table is an error, so a new folder has to be placed in it.
  * firmware/: includes nothing from host_sim/ and, of hal/, only the portable contract
    headers (FIRMWARE_HAL_CONTRACT); never the SocketCAN or MCU drivers.
  * hal/: may include firmware/include (jointguard/...) and its own headers, nothing from
    host_sim/.
  * every pair of host_sim folders that include each other (a cycle) is reported, whatever
    the table says.

Each violating edge is printed as `file:line: folder A includes folder B (not allowed: ...)`,
each cycle as `cycle: folder A and folder B include each other (...)`; the exit code is 1 if
anything was found, 0 otherwise.

  check_layers.py [--root DIR]   check the tree at DIR (default: this repository)
  check_layers.py --self-test    run the check on temporary fake trees with known
                                 violations and a clean one; exit 1 unless it catches them
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

# The host side's layers, lowest first. A folder may include only folders of lower layers.
LAYERS = [
    ("io", ["io"], "recordings, YAML fields, atomic writes, hashing"),
    ("leaf data", ["models", "safety"], "friction model constants, body regions"),
    ("rigid-body dynamics", ["dynamics"], "RNEA/CRBA, regressor, sensitivities, acceleration filter"),
    ("plant", ["plant"], "plant, sensors, collisions, friction truth"),
    ("robot description", ["robot"], "robot files, URDF import, drive files, plant effects"),
    ("motion", ["motion"], "trajectories, excitation, calibration motions"),
    ("simulation", ["sim"], "simulation, scenarios, effects applied to the plant"),
    ("friction identification", ["identification"], "LuGre batch identification"),
    ("whole-arm identification", ["arm_identification"],
     "rigid-body identification, base parameters, physical consistency, constrained fit"),
    ("contact estimation / detection", ["detection", "tuning"], "contact estimate, observer tuning"),
    ("bus primitives", ["can"], "simulated bus, DBC, bus master interface, fault specs"),
    ("evaluation / campaigns", ["eval"], "estimators, evaluation, pipeline, experiments"),
    ("host-in-the-loop", ["hil"], "SocketCAN master, HIL runs"),
    ("diagnosis", ["diagnosis"], "arm level, per joint, plausibility, model-out"),
    ("injection", ["injection"], "injection campaigns"),
    ("report", ["report"], "SVG plots, safety report"),
    ("cli", ["cli"], "the jointguard command line"),
]

# Edges allowed against the table, each with the reason. Keep it empty if at all possible:
# an entry here also silences the cycle it may close (it is printed on every run).
ALLOWED_EXCEPTIONS = {
    # ("from_folder", "to_folder"): "reason",
}

# The hal/ headers the firmware may include: the portable CAN contract, nothing hardware-
# or OS-specific.
FIRMWARE_HAL_CONTRACT = {"jointguard/hal/can.hpp", "jointguard/hal/crc8.hpp", "jointguard/hal/loopback_can.hpp"}

SOURCE_EXT = (".hpp", ".cpp", ".h", ".c", ".hh", ".cc", ".inl", ".ipp")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def layer_index(layers):
    index = {}
    for rank, (name, folders, _) in enumerate(layers):
        for folder in folders:
            index[folder] = (rank, name)
    return index


def source_files(top):
    for dirpath, dirnames, filenames in os.walk(top):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith(SOURCE_EXT):
                yield os.path.join(dirpath, name)


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            m = INCLUDE_RE.match(line)
            if m:
                yield number, m.group(1)


def check(root, layers=LAYERS, exceptions=ALLOWED_EXCEPTIONS, out=sys.stdout):
    """Returns the number of problems found (violating edges, cycles, unplaced folders)."""
    problems = 0
    index = layer_index(layers)
    host = os.path.join(root, "host_sim")
    host_folders = sorted(d for d in os.listdir(host) if os.path.isdir(os.path.join(host, d))) \
        if os.path.isdir(host) else []
    rel = lambda p: os.path.relpath(p, root)

    for folder in host_folders:
        if folder not in index:
            print(f"host_sim/{folder}: folder not in the layer table (scripts/check_layers.py LAYERS)", file=out)
            problems += 1

    # host_sim: folder -> folder edges, with the first place each edge occurs.
    edges = {}
    for folder in host_folders:
        for path in source_files(os.path.join(host, folder)):
            for number, target in includes(path):
                head = target.split("/", 1)[0]
                if "/" not in target or head not in host_folders or head == folder:
                    continue
                edges.setdefault((folder, head), []).append((rel(path), number))
                if (folder, head) in exceptions or folder not in index or head not in index:
                    continue
                (ra, na), (rb, nb) = index[folder], index[head]
                if rb >= ra:
                    why = "same layer" if rb == ra else "higher layer"
                    print(f"{rel(path)}:{number}: folder {folder} includes folder {head} (not allowed: "
                          f"{why}; {folder} is layer {ra} '{na}', {head} is layer {rb} '{nb}', "
                          f"a folder may include only lower layers)", file=out)
                    problems += 1

    for (a, b), where in sorted(edges.items()):
        if a < b and (b, a) in edges and (a, b) not in exceptions and (b, a) not in exceptions:
            back = edges[(b, a)]
            print(f"cycle: folder {a} and folder {b} include each other ({a} -> {b} at "
                  f"{where[0][0]}:{where[0][1]}, {len(where)} include(s); {b} -> {a} at "
                  f"{back[0][0]}:{back[0][1]}, {len(back)} include(s))", file=out)
            problems += 1

    # firmware/ and hal/: nothing from host_sim; firmware only the hal contract headers.
    for tree in ("firmware", "hal"):
        top = os.path.join(root, tree)
        if not os.path.isdir(top):
            continue
        for path in source_files(top):
            for number, target in includes(path):
                head = target.split("/", 1)[0]
                if "/" in target and head in host_folders:
                    print(f"{rel(path)}:{number}: folder {tree} includes folder host_sim/{head} "
                          f"(not allowed: {tree} never includes host code)", file=out)
                    problems += 1
                elif tree == "firmware" and target.startswith("jointguard/hal/") \
                        and target not in FIRMWARE_HAL_CONTRACT:
                    print(f"{rel(path)}:{number}: folder firmware includes folder hal ({target}) "
                          f"(not allowed: the firmware includes only the portable HAL contract "
                          f"{sorted(FIRMWARE_HAL_CONTRACT)})", file=out)
                    problems += 1
    return problems


def self_test():
    """The check run on fake trees: each broken one must fail with the expected line,
    the clean one must pass."""
    script = os.path.abspath(__file__)
    failures = 0

    def tree(files):
        root = tempfile.mkdtemp(prefix="jg_layers_")
        for path, text in files.items():
            full = os.path.join(root, path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)
        return root

    clean = {
        "host_sim/io/a.hpp": "#pragma once\n",
        "host_sim/dynamics/b.hpp": '#include "io/a.hpp"\n',
        "host_sim/eval/c.cpp": '#include "dynamics/b.hpp"\n#include "eval/c.hpp"\n',
        "host_sim/cli/main.cpp": '#include "eval/c.hpp"\n#include "jointguard/scalar.hpp"\n',
        "firmware/include/jointguard/node/n.hpp": '#include "jointguard/hal/can.hpp"\n',
        "hal/socketcan/s.cpp": '#include "jointguard/hal/socketcan.hpp"\n#include "jointguard/node/n.hpp"\n',
    }
    cases = [
        ("clean tree", clean, 0, []),
        ("upward include", dict(clean, **{"host_sim/io/bad.cpp": '\n#include "eval/c.hpp"\n'}), 1,
         ["host_sim/io/bad.cpp:2: folder io includes folder eval (not allowed:"]),
        ("cycle", dict(clean, **{"host_sim/dynamics/x.hpp": '#include "eval/c.hpp"\n'}), 1,
         ["folder dynamics includes folder eval (not allowed:",
          "cycle: folder dynamics and folder eval include each other"]),
        ("same layer", dict(clean, **{"host_sim/models/m.hpp": '#include "safety/s.hpp"\n',
                                      "host_sim/safety/s.hpp": "#pragma once\n"}), 1,
         ["host_sim/models/m.hpp:1: folder models includes folder safety (not allowed: same layer"]),
        ("unplaced folder", dict(clean, **{"host_sim/newfolder/n.hpp": "#pragma once\n"}), 1,
         ["host_sim/newfolder: folder not in the layer table"]),
        ("firmware includes host", dict(clean, **{"firmware/src/f.cpp": '#include "dynamics/b.hpp"\n'}), 1,
         ["firmware/src/f.cpp:1: folder firmware includes folder host_sim/dynamics"]),
        ("firmware includes a driver", dict(clean, **{"firmware/src/g.cpp": '#include "jointguard/hal/socketcan.hpp"\n'}), 1,
         ["firmware/src/g.cpp:1: folder firmware includes folder hal"]),
        ("hal includes host", dict(clean, **{"hal/mcu/h.cpp": '#include "eval/c.hpp"\n'}), 1,
         ["hal/mcu/h.cpp:1: folder hal includes folder host_sim/eval"]),
    ]
    for name, files, want_rc, want_lines in cases:
        root = tree(files)
        try:
            run = subprocess.run([sys.executable, script, "--root", root], capture_output=True, text=True)
        finally:
            shutil.rmtree(root)
        ok = run.returncode == want_rc and all(w in run.stdout for w in want_lines)
        print(f"self-test {name}: {'ok' if ok else 'FAILED'} (exit {run.returncode}, expected {want_rc})")
        if not ok:
            print(run.stdout + run.stderr)
            failures += 1
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    for (a, b), reason in ALLOWED_EXCEPTIONS.items():
        print(f"allowed exception: folder {a} includes folder {b}: {reason}")
    problems = check(args.root)
    print(f"check_layers: {problems} problem(s) in {args.root}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
