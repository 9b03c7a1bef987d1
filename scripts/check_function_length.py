#!/usr/bin/python3
"""Function-length check of the host side (standard library only).

Scans every .cpp and .hpp under host_sim/ for function bodies longer than LIMIT lines and
reports each as `file:line: name N lines` (line: where the body's `{` is; N: the lines from
that `{` to its `}`, both included). The rule (docs/architecture.md "Functions a reader can
hold"): nothing on the host side over about 80 lines without a reason written beside it, in
EXCEPTIONS below.

How a body is found: comments, string literals (raw ones too), character literals and
preprocessor lines are blanked first, so a brace in them counts for nothing; then braces are
matched. A `{` at namespace or class level opens
  * a namespace (`namespace x {`, `extern "C" {`) or a class/struct/union/enum body: looked
    through, the functions inside are scanned;
  * a function body when what stands before it ends with the parameter list (`)`, perhaps
    followed by const, noexcept, override, a trailing return type, a constructor's
    initializer list): everything up to its matching `}` is that function's, lambdas and
    local classes included;
  * anything else (an initializer `= {...}`): skipped.

An exception that is no longer needed (its function is gone or now within the limit) is a
problem too, so the table cannot outlive its reasons. The exit code is 1 if anything was
found, 0 otherwise.

  check_function_length.py [--root DIR] [--limit N]  check the tree at DIR (default: this
                                                     repository)
  check_function_length.py --self-test               run the check on temporary fake trees
                                                     with known long functions, a stale
                                                     exception and a clean tree (with an
                                                     excepted long function); exit 1 unless
                                                     it catches them
"""

import argparse
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fake_tree_selftest import run_cases  # noqa: E402  (beside this script)

LIMIT = 80
SCAN = "host_sim"
SOURCE_EXT = (".cpp", ".hpp")

# (file relative to the root, function name) -> why it may be longer than LIMIT lines.
EXCEPTIONS = {
    # One branch per effect of the catalogue (robot/effect_catalogue.hpp), each a few lines:
    # the effects' regressors (and their descriptions) side by side are what a reader
    # compares when adding or checking an effect; split per effect they would scatter.
    ("host_sim/diagnosis/effects.cpp", "raw_candidate"): "one short branch per catalogue effect (its regressor)",
    ("host_sim/diagnosis/effects.cpp", "describe"): "one short branch per catalogue effect (its parameters in words)",
}

KEYWORDS_NOT_NAMES = {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype",
                      "alignof", "noexcept", "static_assert", "requires"}


def blank(text):
    """The text with comments, string and character literals and preprocessor lines replaced
    by spaces (newlines kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if line_start and c == "#":  # a preprocessor line, with its continuations
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        line_start = False
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")
                                                         or text[i - 1] in "uUL8"):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")  # a digit separator (1'000'000)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def match_brace(code, i):
    """Index of the `}` matching the `{` at i (len(code) if none)."""
    depth = 0
    for j in range(i, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code)


def strip_nested(text, open_, close):
    """The text with everything inside the outermost open_/close pairs removed."""
    out, depth = [], 0
    for c in text:
        if c == open_:
            if depth == 0:
                out.append(c)
            depth += 1
        elif c == close and depth > 0:
            depth -= 1
            if depth == 0:
                out.append(c)
        elif depth == 0:
            out.append(c)
    return "".join(out)


def classify(header):
    """('namespace' | 'class' | 'function' | 'ctor-init' | 'other', name) for the text before a
    `{` at namespace or class level."""
    h = " ".join(header.split())
    if re.search(r"(^|\s)namespace(\s+[\w:]+)?\s*$", h) or re.search(r'extern\s+"C"\s*$', header.strip()) \
            or h == "extern":
        return "namespace", None
    flat = strip_nested(h, "(", ")")
    if re.search(r"(^|[\s>])(class|struct|union|enum)\b", flat) and "=" not in flat.split(":")[0] \
            and not flat.rstrip().endswith(")"):
        return "class", None
    # A constructor's initializer list with a braced member init: `X::X() : a_{1}`: the `{` is
    # the member's, the body comes later.
    if re.search(r"\)\s*(noexcept\s*)?:\s*[\w:]", h) and re.search(r"[\w>]\s*$", h) \
            and not re.search(r"->\s*[\w:<>, ]+$", h):
        return "ctor-init", None
    body_end = re.search(r"\)\s*(const|noexcept|override|final|mutable|volatile|&|&&|\s)*"
                         r"(->\s*[^{;]+)?$", h)
    ctor = re.search(r"\)\s*(noexcept\s*)?:\s*.+[)}]\s*$", h)
    if not (body_end or ctor) or "(" not in h:
        return "other", None
    top = strip_nested(h, "(", ")")
    if "=" in re.sub(r"operator\s*[^\s(]*", "", top).replace("==", "").replace("!=", "") \
            .replace("<=", "").replace(">=", "") and not re.search(r"operator\s*=", h):
        # `auto f = [..](..) {`: a lambda held by a variable at namespace level, named by it.
        m = re.search(r"([A-Za-z_]\w*)\s*(\[[^\]]*\])?\s*=", top)
        return ("function", m.group(1)) if m and "[" in h.split("=", 1)[1] else ("other", None)
    m = re.search(r"(operator\s*(\(\)|\[\]|[^\s(]+))\s*\(", h)
    if m:
        qual = re.search(r"([\w:~]*)\s*$", h[:m.start()])
        return "function", (qual.group(1) if qual else "") + m.group(1).replace(" ", "")
    first = top.find("(")
    m = re.search(r"([A-Za-z_~][\w:~]*)\s*(<[^()]*>)?\s*$", top[:first])
    if not m or m.group(1) in KEYWORDS_NOT_NAMES:
        return "other", None
    return "function", m.group(1)


def functions(code):
    """[(name, first_line, n_lines)] for every function body in blanked code."""
    found = []
    line_of = lambda idx: code.count("\n", 0, idx) + 1

    def scan(lo, hi):
        header_start = lo
        i = lo
        while i < hi:
            c = code[i]
            if c in ";}":
                header_start = i + 1
            elif c == "{":
                kind, name = classify(code[header_start:i])
                end = match_brace(code, i)
                if kind in ("namespace", "class"):
                    scan(i + 1, end)
                    header_start = end + 1
                elif kind == "function":
                    found.append((name, line_of(i), line_of(end) - line_of(i) + 1))
                    header_start = end + 1
                elif kind == "other":
                    header_start = end + 1
                # ctor-init: the braces are part of the header; keep accumulating it.
                i = end
            i += 1

    scan(0, len(code))
    return found


def source_files(top):
    for dirpath, dirnames, filenames in os.walk(top):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith(SOURCE_EXT):
                yield os.path.join(dirpath, name)


def check(root, limit=LIMIT, exceptions=None, out=sys.stdout):
    """Returns (problems, n_functions). Excepted functions are listed with their reason."""
    exceptions = EXCEPTIONS if exceptions is None else exceptions
    problems, count = 0, 0
    used = set()
    for path in source_files(os.path.join(root, SCAN)):
        rel = os.path.relpath(path, root).replace(os.sep, "/")
        with open(path, encoding="utf-8", errors="replace") as f:
            code = blank(f.read())
        for name, line, n in functions(code):
            count += 1
            if n <= limit:
                continue
            key = (rel, name)
            if key in exceptions:
                used.add(key)
                print(f"{rel}:{line}: {name} {n} lines: exception: {exceptions[key]}", file=out)
                continue
            print(f"{rel}:{line}: {name} {n} lines (over {limit}; split it into named stages, or add "
                  f"it to EXCEPTIONS in scripts/check_function_length.py with the reason)", file=out)
            problems += 1
    for key in sorted(set(exceptions) - used):
        print(f"{key[0]}: exception for {key[1]} no longer needed (no such function over {limit} "
              f"lines): remove it from EXCEPTIONS", file=out)
        problems += 1
    return problems, count


def self_test():
    """The check run on fake trees: each with a long function must fail naming it, the clean
    one must pass."""
    script = os.path.abspath(__file__)
    failures = 0


    def body(n, inner="  x += 1;\n"):
        """A `{` ... `}` of exactly n lines."""
        return "{\n" + inner * (n - 2) + "}\n"

    short = ("#include <vector>\nnamespace jg {\nnamespace {\nint helper(int x) " + body(80) + "}  // namespace\n"
             "struct S {\n  int a{1};\n  int get() const " + body(20) + "};\n"
             "const std::vector<int> kTable = {\n" + "  1,\n" * 100 + "};\n"
             "}  // namespace jg\n")
    clean = {"host_sim/io/a.cpp": short, "host_sim/io/a.hpp": "#pragma once\nnamespace jg { int helper(int); }\n",
             "firmware/src/long.cpp": "void firmware_is_not_scanned() " + body(200),
             "host_sim/eval/evaluate.cpp": "int run_detection() " + body(100)}  # excepted
    braces_in_text = ('int quoted() {\n  const char* s = "}}}";\n  char c = \'}\';\n  // }\n  /* } */\n'
                      '  const char* r = R"x(}})x";\n' + "  s++;\n" * 80 + "  return c;\n}\n")
    cases = [
        ("clean tree", clean, 0, []),
        ("81 lines", dict(clean, **{"host_sim/io/b.cpp": "namespace jg {\nint too_long(int x) " + body(81) + "}\n"}),
         1, ["host_sim/io/b.cpp:2: too_long 81 lines"]),
        ("member in a class in a header", dict(clean, **{"host_sim/sim/c.hpp": "#pragma once\nnamespace jg {\nclass C {\n public:\n"
                                                         "  void step(double dt) " + body(90) + "};\n}\n"}),
         1, ["host_sim/sim/c.hpp:5: step 90 lines"]),
        ("qualified, with a lambda inside", dict(clean, **{"host_sim/cli/d.cpp":
                                                           "int Foo::run(int a) const {\n  auto f = [&](int y) {\n"
                                                           + "    y++;\n" * 90 + "  };\n  return 0;\n}\n"}),
         1, ["host_sim/cli/d.cpp:1: Foo::run 95 lines"]),
        ("braces in strings and comments ignored", dict(clean, **{"host_sim/io/e.cpp": braces_in_text}),
         1, ["host_sim/io/e.cpp:1: quoted 88 lines"]),
        ("constructor with braced member inits", dict(clean, **{"host_sim/io/f.cpp":
                                                               "Foo::Foo(int a) : a_{a}, b_(2) " + body(85)}),
         1, ["host_sim/io/f.cpp:1: Foo::Foo 85 lines"]),
        ("lambda held at namespace level", dict(clean, **{"host_sim/io/g.cpp":
                                                         "namespace {\nconst auto kLong = [](int a) " + body(82) + ";\n}\n"}),
         1, ["host_sim/io/g.cpp:2: kLong 82 lines"]),
        ("an exception is per file", dict(clean, **{"host_sim/eval/other.cpp": "int run_detection() " + body(100)}),
         1, ["host_sim/eval/other.cpp:1: run_detection 100 lines"]),
        ("stale exception", dict(clean, **{"host_sim/eval/evaluate.cpp": "int run_detection() " + body(80)}), 1,
         ["host_sim/eval/evaluate.cpp: exception for run_detection no longer needed"]),
    ]
    # The check runs with a table of its own: one exception, for a function the
    # `excepted` cases plant (or leave out: then the entry is stale).
    table = json.dumps([["host_sim/eval/evaluate.cpp", "run_detection", "a reason"]])
    failures += run_cases(lambda root: [sys.executable, script, "--root", root, "--exceptions-json", table], cases, "jg_fnlen_")
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--limit", type=int, default=LIMIT)
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--no-exceptions", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--exceptions-json", help=argparse.SUPPRESS)  # the self-test's table
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    exceptions = {} if args.no_exceptions else EXCEPTIONS
    if args.exceptions_json is not None:
        exceptions = {(path, name): reason for path, name, reason in json.loads(args.exceptions_json)}
    problems, count = check(args.root, args.limit, exceptions)
    print(f"check_function_length: {problems} problem(s) in {args.root}; {count} functions in {SCAN}/, "
          f"{len(exceptions)} exception(s) over {args.limit} lines")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
