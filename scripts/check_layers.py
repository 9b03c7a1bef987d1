#!/usr/bin/python3
"""Layer check of the source tree (standard library only).

Reads the host side's layer table, host_sim/layers.txt (the same file host_sim/CMakeLists.txt
makes the libraries jg_<folder> and their links from, so build and check cannot drift), scans
every `#include "..."` in host_sim/, firmware/ and hal/, and reports:

  * host_sim/: an include of folder B from folder A where A's line does not list B
    (`file:line: folder A includes folder B (not allowed: ...)`). A folder may include exactly
    the folders it lists: a transitive dependency has to be listed to be included directly.
    `jointguard/hal/...` needs `hal` listed, any other `jointguard/...` needs `firmware`.
  * every pair of host_sim folders that include each other (a cycle), whatever the table says;
  * a host_sim folder with no line in the table, a line listing a folder that is not above it
    (the table must stay acyclic) or one that does not exist;
  * firmware/: includes nothing from host_sim/ and, of hal/, only the portable contract
    headers (FIRMWARE_HAL_CONTRACT); hal/: nothing from host_sim/ and nothing from the
    firmware core (jointguard/... outside jointguard/hal/): the HAL sits below the core.
    Board code, which binds the core to a HAL port, lives in boards/.

Listed but unused edges are printed as notes (the table may be tightened), not failures.
The exit code is 1 if anything was found, 0 otherwise.

  check_layers.py [--root DIR]   check the tree at DIR (default: this repository)
  check_layers.py --mermaid      print the table as a mermaid graph (the one in
                                 docs/architecture.md; the check compares the two)
  check_layers.py --self-test    run the check on temporary fake trees with known
                                 violations and a clean one; exit 1 unless it catches them
"""

import argparse
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fake_tree_selftest import run_cases  # noqa: E402  (beside this script)

TABLE = os.path.join("host_sim", "layers.txt")
DOC = os.path.join("docs", "architecture.md")
DOC_BEGIN, DOC_END = "<!-- layers:begin (scripts/check_layers.py --mermaid) -->", "<!-- layers:end -->"
# Dependencies on the trees beside host_sim/, as the table names them.
TOKENS = ("firmware", "hal")

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
LINE_RE = re.compile(r"^([a-z0-9_]+):\s*(.*)$")


def read_table(path, out):
    """[(folder, [deps])] lowest first, and the number of problems in the table itself."""
    table, seen, problems = [], set(), 0
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            m = LINE_RE.match(line)
            if not m:
                print(f"{path}:{number}: not 'folder: deps...': {line!r}", file=out)
                problems += 1
                continue
            folder, deps = m.group(1), m.group(2).split()
            for dep in deps:
                if dep not in TOKENS and dep not in seen:
                    print(f"{path}:{number}: {folder} lists {dep}, which is not a line above it "
                          f"(a folder may use only lower layers)", file=out)
                    problems += 1
            table.append((folder, deps))
            seen.add(folder)
    return table, problems


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


def include_target(target, host_folders):
    """The table's name for what an include reaches: a host_sim folder, `hal`, `firmware`,
    or None (same-folder file, system or third-party header)."""
    if "/" not in target:
        return None
    head = target.split("/", 1)[0]
    if head in host_folders:
        return head
    if target.startswith("jointguard/hal/"):
        return "hal"
    if head == "jointguard":
        return "firmware"
    return None


def check(root, exceptions=ALLOWED_EXCEPTIONS, out=sys.stdout):
    """Returns (problems, edges): the number of problems found and the folder edges seen
    {(from, to): [(file, line), ...]}."""
    rel = lambda p: os.path.relpath(p, root)
    table_path = os.path.join(root, TABLE)
    host = os.path.join(root, "host_sim")
    host_folders = sorted(d for d in os.listdir(host) if os.path.isdir(os.path.join(host, d))) \
        if os.path.isdir(host) else []
    if not os.path.isfile(table_path):
        print(f"{TABLE}: missing (the layer table)", file=out)
        return 1, {}
    table, problems = read_table(table_path, out)
    allowed = dict(table)

    for folder in host_folders:
        if folder not in allowed:
            print(f"host_sim/{folder}: folder not in the layer table ({TABLE})", file=out)
            problems += 1

    edges = {}
    for folder in host_folders:
        for path in source_files(os.path.join(host, folder)):
            for number, target in includes(path):
                to = include_target(target, host_folders)
                if to is None or to == folder:
                    continue
                edges.setdefault((folder, to), []).append((rel(path), number))
                if folder not in allowed or to in allowed[folder] or (folder, to) in exceptions:
                    continue
                names = {f: i for i, (f, _) in enumerate(table)}
                if to in names and names[to] > names[folder]:
                    why = f"{to} is a higher layer than {folder}"
                else:
                    why = f"{folder}'s line in {TABLE} does not list {to}"
                print(f"{rel(path)}:{number}: folder {folder} includes folder {to} (not allowed: {why}; "
                      f"{folder} may include: {' '.join(allowed[folder]) or 'nothing'})", file=out)
                problems += 1

    for (a, b), where in sorted(edges.items()):
        if a < b and (b, a) in edges and (a, b) not in exceptions and (b, a) not in exceptions:
            back = edges[(b, a)]
            print(f"cycle: folder {a} and folder {b} include each other ({a} -> {b} at "
                  f"{where[0][0]}:{where[0][1]}, {len(where)} include(s); {b} -> {a} at "
                  f"{back[0][0]}:{back[0][1]}, {len(back)} include(s))", file=out)
            problems += 1

    for folder, deps in table:
        for dep in deps:
            if (folder, dep) not in edges and os.path.isdir(os.path.join(host, folder)):
                print(f"note: {folder} lists {dep} but includes nothing from it", file=out)

    # firmware/ and hal/: nothing from host_sim; firmware only the hal contract headers; hal
    # nothing of the core.
    for tree in ("firmware", "hal"):
        top = os.path.join(root, tree)
        if not os.path.isdir(top):
            continue
        for path in source_files(top):
            for number, target in includes(path):
                to = include_target(target, host_folders)
                if to in host_folders:
                    print(f"{rel(path)}:{number}: folder {tree} includes folder host_sim/{to} "
                          f"(not allowed: {tree} never includes host code)", file=out)
                    problems += 1
                elif tree == "firmware" and to == "hal" and target not in FIRMWARE_HAL_CONTRACT:
                    print(f"{rel(path)}:{number}: folder firmware includes folder hal ({target}) "
                          f"(not allowed: the firmware includes only the portable HAL contract "
                          f"{sorted(FIRMWARE_HAL_CONTRACT)})", file=out)
                    problems += 1
                elif tree == "hal" and to == "firmware":
                    print(f"{rel(path)}:{number}: folder hal includes the firmware core ({target}) "
                          f"(not allowed: the HAL sits below the core; code binding the core to "
                          f"a port is board code, boards/)", file=out)
                    problems += 1

    problems += check_doc(root, table, out)
    return problems, edges


def mermaid(table):
    """The table as a mermaid graph, drawn as its transitive reduction (an arrow the others
    already imply is left out; the table lists it)."""
    deps = {f: set(d) for f, d in table}
    reach = {}
    for f, _ in table:  # lowest first, so every dep's reach is known
        reach[f] = set()
        for d in deps[f]:
            reach[f] |= {d} | reach.get(d, set())
    lines = ["```mermaid", "graph BT"]
    for f, _ in table:
        for d in sorted(deps[f]):
            implied = any(d in reach.get(o, set()) for o in deps[f] if o != d)
            if not implied:
                lines.append(f"  {f} --> {d}")
    lines.append("```")
    return "\n".join(lines)


def check_doc(root, table, out):
    """docs/architecture.md's diagram must be the one the table gives, and its table must
    have a row per folder (skipped in a tree without that page, e.g. the self-test's)."""
    path = os.path.join(root, DOC)
    if not os.path.isfile(path):
        return 0
    text = open(path, encoding="utf-8").read()
    if DOC_BEGIN not in text or DOC_END not in text:
        print(f"{DOC}: the layer diagram's markers are missing ({DOC_BEGIN})", file=out)
        return 1
    problems = 0
    shown = text.split(DOC_BEGIN, 1)[1].split(DOC_END, 1)[0].strip()
    if shown != mermaid(table):
        print(f"{DOC}: the layer diagram differs from {TABLE}; paste the output of "
              f"`scripts/check_layers.py --mermaid` between the markers", file=out)
        problems += 1
    for folder, _ in table:
        if f"| `{folder}` (" not in text:
            print(f"{DOC}: no row for folder {folder} in the host layers table", file=out)
            problems += 1
    return problems


def self_test():
    """The check run on fake trees: each broken one must fail with the expected line,
    the clean one must pass."""
    script = os.path.abspath(__file__)
    failures = 0


    table = "# fake\nio:\nmodels: firmware\nsafety:\ndynamics: io\neval: dynamics io\ncli: eval firmware\n"
    clean = {
        TABLE: table,
        "host_sim/io/a.hpp": "#pragma once\n",
        "host_sim/models/m.hpp": '#include "jointguard/numeric/q.hpp"\n',
        "host_sim/safety/s.hpp": "#pragma once\n",
        "host_sim/dynamics/b.hpp": '#include "io/a.hpp"\n#include <vector>\n',
        "host_sim/eval/c.cpp": '#include "dynamics/b.hpp"\n#include "eval/c.hpp"\n#include "io/a.hpp"\n',
        "host_sim/cli/main.cpp": '#include "eval/c.hpp"\n#include "jointguard/scalar.hpp"\n',
        "firmware/include/jointguard/node/n.hpp": '#include "jointguard/hal/can.hpp"\n',
        "hal/socketcan/s.cpp": '#include "jointguard/hal/socketcan.hpp"\n',
    }
    cases = [
        ("clean tree", clean, 0, []),
        ("planted back-edge", dict(clean, **{"host_sim/io/bad.cpp": '\n#include "eval/c.hpp"\n'}), 1,
         ["host_sim/io/bad.cpp:2: folder io includes folder eval (not allowed: eval is a higher layer than io"]),
        ("cycle", dict(clean, **{"host_sim/dynamics/x.hpp": '#include "eval/c.hpp"\n'}), 1,
         ["host_sim/dynamics/x.hpp:1: folder dynamics includes folder eval (not allowed:",
          "cycle: folder dynamics and folder eval include each other"]),
        ("unlisted transitive", dict(clean, **{"host_sim/cli/t.cpp": '#include "dynamics/b.hpp"\n'}), 1,
         ["host_sim/cli/t.cpp:1: folder cli includes folder dynamics (not allowed: cli's line"]),
        ("same layer side step", dict(clean, **{"host_sim/models/x.hpp": '#include "safety/s.hpp"\n'}), 1,
         ["host_sim/models/x.hpp:1: folder models includes folder safety (not allowed:"]),
        ("firmware not listed", dict(clean, **{"host_sim/io/f.hpp": '#include "jointguard/numeric/q.hpp"\n'}), 1,
         ["host_sim/io/f.hpp:1: folder io includes folder firmware (not allowed:"]),
        ("unplaced folder", dict(clean, **{"host_sim/newfolder/n.hpp": "#pragma once\n"}), 1,
         ["host_sim/newfolder: folder not in the layer table"]),
        ("table lists a higher layer", dict(clean, **{TABLE: table.replace("dynamics: io", "dynamics: io eval")}), 1,
         ["host_sim/layers.txt:5: dynamics lists eval, which is not a line above it"]),
        ("firmware includes host", dict(clean, **{"firmware/src/f.cpp": '#include "dynamics/b.hpp"\n'}), 1,
         ["firmware/src/f.cpp:1: folder firmware includes folder host_sim/dynamics"]),
        ("firmware includes a driver", dict(clean, **{"firmware/src/g.cpp": '#include "jointguard/hal/socketcan.hpp"\n'}), 1,
         ["firmware/src/g.cpp:1: folder firmware includes folder hal"]),
        ("hal includes host", dict(clean, **{"hal/mcu/h.cpp": '#include "eval/c.hpp"\n'}), 1,
         ["hal/mcu/h.cpp:1: folder hal includes folder host_sim/eval"]),
        ("hal includes the core (a board file)", dict(clean, **{"hal/mcu/t.cpp": '#include "jointguard/node/n.hpp"\n'}), 1,
         ["hal/mcu/t.cpp:1: folder hal includes the firmware core"]),
        ("stale diagram", dict(clean, **{DOC: f"{DOC_BEGIN}\n```mermaid\ngraph BT\n```\n{DOC_END}\n"}), 1,
         ["docs/architecture.md: the layer diagram differs"]),
    ]
    failures += run_cases(lambda root: [sys.executable, script, "--root", root], cases, "jg_layers_")
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--mermaid", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if args.mermaid:
        table, problems = read_table(os.path.join(args.root, TABLE), sys.stderr)
        print(mermaid(table))
        return 1 if problems else 0
    for (a, b), reason in ALLOWED_EXCEPTIONS.items():
        print(f"allowed exception: folder {a} includes folder {b}: {reason}")
    problems, edges = check(args.root)
    host = sum(1 for (a, b) in edges if b not in TOKENS)
    print(f"check_layers: {problems} problem(s) in {args.root}; {host} host_sim folder edges, "
          f"{len(edges) - host} to firmware/hal, {sum(len(w) for w in edges.values())} includes checked")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
