#!/usr/bin/python3
"""Known causes injected into real recordings, then diagnosed against the robot file alone.

Usage: injection_bench.py JOINTGUARD DATA_DIR ARM [--cases N] [--json OUT]
  ARM: panda (panda-excitation, models/panda.yaml, joint torque sensor) or ur10e
  (ur10e-static/motion_free.csv, vendor URDF + drive.yaml, motor currents).

Cases: payloads at the flange from the noise floor up to the arm's rating (mass on a grid,
centre of mass drawn from a fixed list), and zero-size injections (an empty list, a payload
of zero first moment and tiny mass, a Coulomb change of 0). Scored:
  - payload: named at the arm level, its mass within 20 % of the injected one;
  - wrong: a payload claimed with a mass off by more than 20 % (a wrong claim);
  - zero-size: nothing claimed beyond what the untouched recording gives.
Only the Python standard library (the CI machine's /usr/bin/python3).
"""
import json
import os
import subprocess
import sys
import tempfile

ARMS = {
    "panda": {
        "recording": "panda-excitation/panda_excitation.csv",
        "model": ["--model", "models/panda.yaml", "--torque-kind", "joint"],
        "link": 7,
        "masses": [0.3, 0.5, 0.8, 1.0, 1.5, 2.0, 2.5, 2.8],
    },
    "ur10e": {
        "recording": "ur10e-static/motion_free.csv",
        "model": ["--model", "{data}/ur10e-static/ur10e.urdf", "--drive", "{data}/ur10e-static/drive.yaml"],
        "link": 6,
        "masses": [0.5, 1.0, 2.4, 4.0, 6.0, 8.0, 10.0, 12.0],
    },
}
CENTRES_M = [(0.0, 0.0, 0.05), (0.0, 0.0, 0.1), (0.03, 0.0, 0.08), (0.0, -0.03, 0.12)]


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return r.stdout


def claims(diag):
    out = {("arm", f["effect"]) for f in diag["arm"]["findings"]}
    for j in diag["joints"]:
        out |= {(j["joint"], f["effect"]) for f in j["findings"] if f["effect"] != "none"}
    return out


def payloads(diag):
    return [f["params"]["mass_kg"] for f in diag["arm"]["findings"] if f["effect"] == "payload"]


def main():
    args = sys.argv[1:]
    if len(args) < 3 or args[2] not in ARMS:
        raise SystemExit(__doc__)
    jg, data, arm_name = args[0], args[1], args[2]
    count = int(args[args.index("--cases") + 1]) if "--cases" in args else None
    out_json = args[args.index("--json") + 1] if "--json" in args else None
    arm = ARMS[arm_name]
    model = [a.format(data=data) for a in arm["model"]]
    recording = os.path.join(data, arm["recording"])
    cases = []
    for i, m in enumerate(arm["masses"]):
        for k in range(2):  # two centres per mass, rotating through the list
            cases.append(("payload", m, CENTRES_M[(i + k) % len(CENTRES_M)]))
    zero = [("empty", 0.0, None), ("coulomb0", 0.0, None)]
    if count is not None:  # a small version: spread over the sizes, zero-size cases kept
        step = max(1, len(cases) // max(count, 1))
        cases = cases[::step][:count]
    work = tempfile.mkdtemp(prefix="jg_inject_")
    base_json = os.path.join(work, "untouched.json")
    run([jg, "diagnose", "--real", recording, *model, "--json", base_json])
    base = json.load(open(base_json))
    base_claims = claims(base)
    rows = []
    for n, (kind, mass, centre) in enumerate(cases + zero):
        effects = os.path.join(work, f"e{n}.yaml")
        with open(effects, "w") as f:
            if kind == "payload":
                h = [mass * x for x in centre]
                f.write("plant_effects:\n  - {effect: payload, joint: 0, setting: {link: %d}, coefficients: [%r, %r, %r, %r]}\n"
                        % (arm["link"], mass, h[0], h[1], h[2]))
            elif kind == "empty":
                f.write("plant_effects: []\n")
            else:
                f.write("plant_effects:\n  - {effect: coulomb, joint: 2, coefficients: [0.0]}\n")
        rec = os.path.join(work, f"r{n}.csv")
        run([jg, "inject", recording, *model, "--effects", effects, "--out", rec])
        dj = os.path.join(work, f"d{n}.json")
        run([jg, "diagnose", "--real", rec, *model, "--json", dj])
        d = json.load(open(dj))
        named = payloads(d)
        row = {"kind": kind, "mass_kg": mass, "centre_m": centre, "named_kg": named}
        if kind == "payload":
            row["named"] = bool(named) and abs(named[0] - mass) <= 0.2 * mass
            row["wrong"] = bool(named) and not row["named"]
        else:
            row["extra_claims"] = sorted(map(str, claims(d) - base_claims))
        rows.append(row)
        print(json.dumps(row), flush=True)
    pay = [r for r in rows if r["kind"] == "payload"]
    zer = [r for r in rows if r["kind"] != "payload"]
    summary = {
        "arm": arm_name,
        "payload_cases": len(pay),
        "named_within_20pct": sum(r["named"] for r in pay),
        "wrong_claims": sum(r["wrong"] for r in pay),
        "zero_size_cases": len(zer),
        "zero_size_with_extra_claims": sum(bool(r["extra_claims"]) for r in zer),
        "untouched_arm_findings": [f["effect"] for f in base["arm"]["findings"]],
    }
    print(json.dumps(summary))
    if out_json:
        json.dump({"summary": summary, "cases": rows}, open(out_json, "w"), indent=1)


if __name__ == "__main__":
    main()
