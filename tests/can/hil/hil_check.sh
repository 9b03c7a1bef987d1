#!/usr/bin/env bash
# Host side of can.hil_socketcan: hil_check.sh OUT_DIR JOINTGUARD PAYLOAD_DIR
#  - the plant detected the push on link 2 and the drives sent collision events;
#  - every captured frame decodes with docs/can/jointguard.dbc, and the product traffic per
#    cycle is what the simulated bus model counts (8 frames for 3 joints);
#  - the same scenario with the drives in-process on the simulated bus gives the same
#    estimates, cycle for cycle and bit for bit (CSV traces identical).
set -euo pipefail
out=$1 jg=$2 payload=$3
fail() { echo "hil_check: FAIL: $*" >&2; exit 1; }
command -v /usr/bin/python3 >/dev/null || fail "/usr/bin/python3 is needed to read the JSON results"
/usr/bin/python3 - "$out/plant.json" <<'PY' || fail "plant results"
import json, sys
j = json.load(open(sys.argv[1]))
r = j["runs"][0]
assert r["t_detected"] is not None, "no detection"
assert r["link_isolated"] == 2, f"isolated link {r['link_isolated']}"
assert 0 < r["delay"] < 0.05, f"delay {r['delay']}"
assert any(e["joint"] == 2 for e in j["events"]), "no collision event from joint 2"
assert j["bus"]["rejected"] == 0 and j["bus"]["out_of_cycle"] == 0, j["bus"]
print(f"hil_check: detected at {r['t_detected']:.3f} s (delay {1e3*r['delay']:.1f} ms), link {r['link_isolated']}, "
      f"{len(j['events'])} collision events, {j['bus']['cycles']} cycles")
PY
"$jg" decode "$out/capture.log" --json "$out/traffic.json" || fail "capture does not decode with the DBC"
/usr/bin/python3 - "$out/traffic.json" "$out/plant.json" <<'PY' || fail "traffic"
import json, sys
t = json.load(open(sys.argv[1])); p = json.load(open(sys.argv[2]))
cycles = p["bus"]["cycles"]
m = t["messages"]
# The master repeats cycle 0 until every node answers (start-up), so a sync or two extra.
assert cycles <= m["CYCLE_SYNC"] <= cycles + 5, (m, cycles)
per_cycle = sum(m[f"{k}_J{j}"] for k in ("OUTWARD", "INWARD") for j in (1, 2, 3) if f"{k}_J{j}" in m) / cycles
assert per_cycle == 4.0, f"momentum messages per cycle {per_cycle}: 2(n-1) = 4 expected"
for j in (1, 2, 3):
    # plus the start-up announcements; a reacting drive's status is REACTION_STATUS_Jj
    assert cycles <= m[f"STATUS_J{j}"] + m.get(f"REACTION_STATUS_J{j}", 0) <= cycles + 100, m
    assert m[f"SENSOR_J{j}"] >= cycles, m
    # The detection's reaction (stop) commanded by the master and run by every drive on SocketCAN.
    assert m.get(f"REACTION_STATUS_J{j}", 0) > 0, f"drive {j} never sent a reaction status: {m}"
per = t["product_frames_per_cycle"]
# Wire time of the captured product traffic at 1/5 Mbit/s: the simulated bus model's figure
# for 3 joints (tests/can/test_sim_bus.cpp, docs/can.md), one-off frames aside.
assert 8.0 <= per < 8.002, per  # 4 momentum + 3 status + sync, plus a one-off collision event or two
assert abs(t["product_wire_us_per_cycle"] - 775.2) < 0.5, t["product_wire_us_per_cycle"]
print(f"hil_check: capture {t['frames']} frames, {per:.3f} product frames and {t['product_wire_us_per_cycle']:.0f} us of "
      f"wire time per cycle at 1/5 Mbit/s")
PY
for j in 1 2 3; do
  # A stale sync or two: the master repeats cycle 0 until every node has answered.
  /usr/bin/python3 -c "import json,sys; n=json.load(open(sys.argv[1])); r=n['rejected']; s=r.pop('stale_sync'); assert sum(r.values())==0 and s<=5 and not n['communication_fault'], n; x=n['reaction']; assert x['kind']=='stop' and x['cycles']>0 and x['commands_rejected']==0, x" \
    "$out/node$j.json" || fail "node $j counters"
done
"$jg" plant "$payload/hil_shoulder.yaml" --bus sim --friction "$payload/friction.json" --threshold "$payload/threshold.json" \
  --trace "$out/trace_sim.csv" --out "$out/rec_sim.csv" >"$out/plant_sim.txt" || fail "in-process run"
cmp "$out/trace.csv" "$out/trace_sim.csv" || fail "SocketCAN and in-process simulated-bus estimates differ"
echo "hil_check: SocketCAN run and in-process run identical over $(($(wc -l <"$out/trace.csv") - 1)) cycles"

# Seven joints: 2(n-1) = 12 momentum messages, 7 status frames and a sync per cycle, 2100 us
# of wire time at 1/5 Mbit/s (the bus-load table's 7-joint row).
"$jg" decode "$out/capture7.log" --json "$out/traffic7.json" >/dev/null || fail "7-joint capture does not decode with the DBC"
/usr/bin/python3 - "$out/traffic7.json" "$out/plant7.json" <<'PY' || fail "7-joint traffic"
import json, sys
t = json.load(open(sys.argv[1])); p = json.load(open(sys.argv[2]))
cycles = p["bus"]["cycles"]; m = t["messages"]
momentum = sum(m.get(f"{k}_J{j}", 0) for k in ("OUTWARD", "INWARD") for j in range(1, 8)) / cycles
assert momentum == 12.0, momentum
for j in range(1, 8):
    # plus the start-up announcements; a reacting drive's status is REACTION_STATUS_Jj
    assert cycles <= m[f"STATUS_J{j}"] + m.get(f"REACTION_STATUS_J{j}", 0) <= cycles + 100, m
assert cycles <= m["CYCLE_SYNC"] <= cycles + 5, (m, cycles)
assert abs(t["product_wire_us_per_cycle"] - 2100.0) < 0.5, t["product_wire_us_per_cycle"]
print(f"hil_check: 7 joints: {t['product_frames_per_cycle']:.3f} product frames and {t['product_wire_us_per_cycle']:.0f} us "
      f"of wire time per cycle at 1/5 Mbit/s over {cycles} cycles")
PY
"$jg" plant "$payload/panda_traffic.yaml" --bus sim --threshold "$payload/threshold7.json" --trace "$out/trace7_sim.csv" \
  >"$out/plant7_sim.txt" || fail "in-process 7-joint run"
cmp "$out/trace7.csv" "$out/trace7_sim.csv" || fail "7 joints: SocketCAN and in-process estimates differ"
echo "hil_check: 7 joints: SocketCAN run and in-process run identical"

# Faults mid-run (hil_payload.sh): the run goes on to its end (no abort), the master raises the
# communication fault within 5 cycles of the first cycle it closed without a drive and the
# arm holds, the faulted drive's neighbours report it themselves (restart, late, bus-off),
# and at the end every drive is back: the restarted drive 2 ran again from a sync, no drive
# and not the master has a fault left. The faults given by spec start at cycle 500.
/usr/bin/python3 - "$out" <<'PY' || fail "faults mid-run on SocketCAN"
import json, re, sys
out = sys.argv[1]
for fault in ("restart", "linkdown", "late", "busoff", "babble", "frames"):
    p = json.load(open(f"{out}/plant_{fault}.json"))
    text = open(f"{out}/plant_{fault}.txt").read()
    r, bus = p["runs"][0], p["bus"]
    first = re.search(r"cycle (\d+) closed without joint", text)
    assert first, f"{fault}: the master never closed a cycle without a drive"
    k0 = int(first.group(1))
    assert r["t_comm_fault"] is not None, f"{fault}: no communication fault"
    detect = round(r["t_comm_fault"] * 1000) - k0
    assert 0 <= detect <= 5, f"{fault}: communication fault {detect} cycles after cycle {k0}"
    assert bus["cycles"] == 2201, f"{fault}: run ended early after {bus['cycles']} cycles"
    assert not bus["communication_fault_at_end"], f"{fault}: the master still sees a fault at the end"
    nodes = {j: json.load(open(f"{out}/{fault}_node{j}.json")) for j in (1, 3)}
    nodes[2] = json.load(open(f"{out}/{'restarted' if fault == 'restart' else fault}_node2.json"))
    for j, n in nodes.items():
        assert not n["communication_fault"], f"{fault}: drive {j} still has a communication fault"
    fc = bus["first_comm_fault_cycle"]
    extra = ""
    if fault in ("late", "busoff", "babble", "frames"):
        assert 500 <= k0 <= 505, f"{fault}: injected from cycle 500, first cycle without a drive {k0}"
    if fault in ("late", "busoff", "frames"):
        # Drive 2's neighbours hear no fresh frame from it: their own fault by the 6th cycle.
        assert k0 <= fc[0] <= k0 + 6 and k0 <= fc[2] <= k0 + 6, f"{fault}: neighbours' fault at cycles {fc}, drive 2 silent from {k0}"
        assert fc[1] == -1, f"{fault}: drive 2 itself heard its neighbours all along: {fc}"
    if fault == "late":
        f2 = nodes[2]["faults"]
        assert 3 * 199 <= f2["frames_delayed"] <= 3 * 201, f"late: drive 2 delayed {f2['frames_delayed']} frames (3 per cycle x 200)"
        assert nodes[1]["rejected"]["late"] + nodes[3]["rejected"]["late"] > 100, "late: the neighbours counted no late frame"
        assert bus["out_of_cycle"] > 100, f"late: the master counted {bus['out_of_cycle']} statuses of another cycle"
        extra = f", {f2['frames_delayed']} frames held 10 cycles, {bus['out_of_cycle']} out-of-cycle statuses at the master"
    if fault == "busoff":
        f2 = nodes[2]["faults"]
        assert f2["bus_off_entries"] == 1 and f2["bus_off_recoveries"] == 1 and not f2["bus_off_at_end"], f2
        assert f2["refused_bus_off"] >= 2 * 199, f"bus-off: {f2['refused_bus_off']} sends refused"
        assert nodes[2]["send_failures"] >= 199, nodes[2]
        extra = f", drive 2 bus-off and restarted once, {f2['refused_bus_off']} sends refused"
    if fault == "babble":
        m = re.search(r"babbler sent (\d+) frames; the master lost arbitration (\d+) times", text)
        assert m and int(m.group(1)) > 1000 and int(m.group(2)) >= 190, f"babble: {m and m.group(0)}"
        assert bus["rejected"] > 1000, f"babble: the master rejected {bus['rejected']} frames (the babbled garbage)"
        # The babbled identifier is joint 1's collision event: none taken while it babbled
        # (after it, the drives' own events of the warm-up at a standstill are real frames).
        babbled = [e for e in p["events"] if e["joint"] == 1 and 500 <= e["cycle"] < 700]
        assert not babbled, f"babble: babbled frames taken as joint 1's collision event: {babbled}"
        extra = f", {m.group(0)}, {bus['rejected']} babbled frames rejected"
    if fault == "restart":
        assert bus["restarts"] == 1, bus
        assert nodes[2]["cycles"] > 100, f"restarted drive 2 ran {nodes[2]['cycles']} cycles"
        assert fc[0] >= k0 and fc[2] >= k0, f"neighbours did not report drive 2 silent: {fc}"
    print(f"hil_check: {fault}: drive(s) silent from cycle {k0}, communication fault {detect} cycles later, "
          f"arm held, all drives back at the end (restarts {bus['restarts']}, drives' own fault at cycles {fc}){extra}")
PY

# The master's frame faults in four windows of one run (hil_payload.sh, docs/can.md "On
# SocketCAN"), each in its documented state, and the run the same as the same specs on the
# simulated bus in-process: identical estimates cycle for cycle and identical fault spans.
specs=()
while IFS= read -r spec; do specs+=(--fault "$spec"); done < <(/usr/bin/python3 -c \
  'import json,sys; print("\n".join(json.load(open(sys.argv[1]))["faults"]))' "$out/plant_frames.json")
[ "${#specs[@]}" = 10 ] || fail "frames: the SocketCAN run's JSON lists ${#specs[@]} / 2 fault specs, 5 expected"
"$jg" plant "$payload/hil_shoulder.yaml" --bus sim --friction "$payload/friction.json" --threshold "$payload/threshold.json" \
  "${specs[@]}" --trace "$out/trace_frames_sim.csv" --json "$out/plant_frames_sim.json" >"$out/plant_frames_sim.txt" ||
  fail "in-process run with the frame faults"
cmp "$out/trace_frames.csv" "$out/trace_frames_sim.csv" || fail "frames: SocketCAN and in-process estimates differ"
/usr/bin/python3 - "$out" <<'PY' || fail "frame faults mid-run on SocketCAN"
import csv, json, sys
out = sys.argv[1]
p, sim = json.load(open(f"{out}/plant_frames.json")), json.load(open(f"{out}/plant_frames_sim.json"))
nodes = {j: json.load(open(f"{out}/frames_node{j}.json")) for j in (1, 2, 3)}
r, bus = p["runs"][0], p["bus"]
eps = [(e["fault"], e["joint"], e["from_cycle"], e["to_cycle"]) for e in p["fault_episodes"]]
assert eps == [(e["fault"], e["joint"], e["from_cycle"], e["to_cycle"]) for e in sim["fault_episodes"]], \
    f"fault spans differ from the simulated bus: {eps} vs {sim['fault_episodes']}"
assert all(to is not None for *_, to in eps), f"a fault still raised at the end: {eps}"
assert not bus["input_fault_at_end"] and not bus["communication_fault_at_end"], bus
def spans(fault, start, end):  # (joint, from, to) of the spans of `fault` beginning in [start, end)
    return [(j, a, b) for f, j, a, b in eps if f == fault and start <= a < end]
def master_raised(fault, start, within):
    s = [(a, b) for j, a, b in spans(fault, start, start + 200) if j == 0]
    assert s and s[0][0] - start <= within, f"{fault} fault of the window from cycle {start}: master spans {s}"
    return s[0]
lines = []
# duplicate (sync and drive 2's samples, cycles 300-349): absorbed, no fault, the estimates
# those of the fault-free run; every duplicated sync recognised as stale by every drive.
assert not [e for e in eps if e[2] < 500], f"duplicates raised a fault: {eps}"
with open(f"{out}/trace_frames.csv") as a, open(f"{out}/trace.csv") as b:
    assert [next(a) for _ in range(501)] == [next(b) for _ in range(501)], "duplicates changed an estimate before cycle 500"
stale = [nodes[j]["rejected"]["stale_sync"] for j in (1, 2, 3)]
assert all(50 <= s <= 55 for s in stale), f"duplicate: stale syncs {stale} (50 duplicated, a few at start-up)"
lines.append(f"duplicate: no fault, estimates identical to the fault-free run, stale syncs per drive {stale}")
# drop (drive 2's samples, cycles 500-549) and corrupt (800-849): no cycle runs on them,
# drive 2 silent: the master in the 5th cycle, drives 1 and 3 by the 6th; all clear again
# after the window. Drive 2 rejected exactly the corrupted samples.
for kind, k in (("drop", 500), ("corrupt", 800)):
    a, b = master_raised("communication", k, 4)
    near = spans("communication", k, k + 50)
    for j in (1, 3):
        assert any(jj == j and aa - k <= 5 for jj, aa, _ in near), f"{kind}: drive {j} did not report drive 2: {near}"
    assert not any(jj == 2 for jj, *_ in near), f"{kind}: drive 2 heard its neighbours all along: {near}"
    assert all(bb <= k + 60 for _, _, bb in near), f"{kind}: not clear again within 10 cycles of the window's end: {near}"
    lines.append(f"{kind}: communication fault (master) cycles {a}-{b}, drives 1 and 3 from "
                 f"{[aa for jj, aa, _ in near if jj in (1, 3)]}")
assert nodes[2]["rejected"]["sensor"] == 50, f"corrupt: drive 2 rejected {nodes[2]['rejected']['sensor']} samples, 50 corrupted"
cycles = [nodes[j]["cycles"] for j in (1, 2, 3)]
assert cycles[0] == cycles[2] == 2201 and cycles[1] == 2101, f"cycles run per drive {cycles}: 100 without a sample on drive 2"
# nan-sensor (drive 2, 1100-1149): input fault in the same cycle, no communication fault
# (the neighbours run on its repeated messages), clear after the window.
a, b = master_raised("input", 1100, 0)
assert sorted(spans("input", 1100, 1300)) == [(0, 1100, b), (2, 1100, b)], f"nan-sensor: input fault spans {eps}"
assert not spans("communication", 1100, 1300), f"nan-sensor raised a communication fault: {eps}"
assert bus["invalid_samples_sent"] == 50, bus
assert round(r["t_comm_fault"] * 1000) == 504 and round(r["t_input_fault"] * 1000) == 1100, r
lines.append(f"nan-sensor: input fault (master, drive 2) cycles {a}-{b}, {bus['invalid_samples_sent']} samples sent marked invalid")
# The arm holds from 0.1 s after the first fault to the end (push at 1.5 s included), where
# the fault-free arm moves on.
def drift(path, t0):
    rows = [row for row in csv.DictReader(open(path)) if float(row["t"]) >= t0 - 1e-9]
    return max(abs(float(row[q]) - float(rows[0][q])) for row in rows for q in ("q1", "q2", "q3"))
held, free = drift(f"{out}/rec_frames.csv", 0.604), drift(f"{out}/rec_sim.csv", 0.604)
assert held < 0.01 < 0.1 < free, f"drift after the hold {held} rad (fault-free {free} rad)"
for line in lines:
    print(f"hil_check: frames: {line}")
print(f"hil_check: frames: arm held ({held:.4f} rad drift from 0.604 s; fault-free {free:.2f} rad); events {p['events']}; "
      f"identical to the simulated bus (estimates and fault spans); {bus['cycles']} cycles")
PY
