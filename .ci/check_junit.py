#!/usr/bin/env python3
"""`taxi-sim regress`'s JUnit XML read back by a third-party reader (PyPI junitparser) and
checked case by case against its JSON lines: the same cases, each with the status the JSON
gives (passed: no result; failed: failure; error: error; known_problem and not_run: skipped,
a known problem's message carrying its text), the seed and rerun command as properties.

Usage: check_junit.py RESULTS.xml RESULTS.jsonl
Exit code 1 with every mismatch listed; 0 and a one-line summary otherwise.
"""
import json
import sys

from junitparser import Error, Failure, JUnitXml, Properties, Skipped


def main(xml_path, json_path):
    cases = [json.loads(line) for line in open(json_path) if line.strip()]
    want = {(c["suite"], c["name"]): c for c in cases}
    problems = []
    seen = set()
    xml = JUnitXml.fromfile(xml_path)
    for suite in xml:
        for case in suite:
            key = (suite.name, case.name)
            if key in seen:
                problems.append(f"{key}: twice in the XML")
            seen.add(key)
            c = want.get(key)
            if c is None:
                problems.append(f"{key}: in the XML, not in the JSON")
                continue
            kinds = [type(r) for r in case.result]
            expected = {
                "passed": [],
                "failed": [Failure],
                "error": [Error],
                "known_problem": [Skipped],
                "not_run": [Skipped],
            }[c["status"]]
            if kinds != expected:
                problems.append(f"{key}: JSON says {c['status']}, XML has {[k.__name__ for k in kinds]}")
            if c["status"] == "known_problem" and c["known_problem"] not in (case.result[0].message or ""):
                problems.append(f"{key}: the skipped message does not carry the known problem's text")
            found = case.child(Properties)
            props = {p.name: p.value for p in found} if found is not None else {}
            if props.get("seed") != str(c["seed"]) or props.get("rerun") != c["rerun"]:
                problems.append(f"{key}: properties {props} do not match the JSON")
            if abs(case.time - c["wall_time_s"]) > 0.01:
                problems.append(f"{key}: time {case.time} against {c['wall_time_s']} in the JSON")
    for key in want.keys() - seen:
        problems.append(f"{key}: in the JSON, not in the XML")
    if problems:
        print("\n".join(problems))
        return 1
    counts = {}
    for c in cases:
        counts[c["status"]] = counts.get(c["status"], 0) + 1
    print(f"ok: junitparser read {len(seen)} cases in {len(list(xml))} suites, each as the JSON says: {counts}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
