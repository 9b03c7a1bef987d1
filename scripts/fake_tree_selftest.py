"""The self-test harness the source-tree checks share (check_layers.py,
check_function_length.py): each case is a fake tree written to a temporary folder, the check
run on it, its exit code and the lines it must print compared. Standard library only."""

import os
import shutil
import subprocess
import tempfile


def make_tree(files, prefix):
    """A temporary folder holding {relative path: text}; the caller removes it."""
    root = tempfile.mkdtemp(prefix=prefix)
    for path, text in files.items():
        full = os.path.join(root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)
    return root


def run_cases(command_for_root, cases, prefix):
    """Runs command_for_root(root) on each (name, files, want_rc, want_lines) case, prints
    one line per case and the output of a failed one; returns the number that failed."""
    failures = 0
    for name, files, want_rc, want_lines in cases:
        root = make_tree(files, prefix)
        try:
            run = subprocess.run(command_for_root(root), capture_output=True, text=True)
        finally:
            shutil.rmtree(root)
        ok = run.returncode == want_rc and all(w in run.stdout for w in want_lines)
        print(f"self-test {name}: {'ok' if ok else 'FAILED'} (exit {run.returncode}, expected {want_rc})")
        if not ok:
            print(run.stdout + run.stderr)
            failures += 1
    return failures
